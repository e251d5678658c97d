"""Ground-truth groups of a synthetic scene.

Membership comes from the scene (the layout says who talks with whom). The interest point and the area of the
interaction zone are those the group detector (``sid.perception.groups.detect_groups``) computes on the *exact* people
of the group (true positions and facing directions, only the members, the same parameters), so the reference follows the
detector's own definition of the zone (ray crossings, shoelace area and centroid) and an error measured against it comes
from perception alone. In the S1-S5 layouts without jitter every member faces the formation centre, so the area is 0 and
the interest point is the centre (S4 included: its two outer members' rays cross at the centre too).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from sid.perception.groups import GroupParams, detect_groups
from sid.synthetic.scene import ScenePerson

__all__ = ["TruthGroup", "truth_groups"]


@dataclass(frozen=True)
class TruthGroup:
    """A true group: member ids; interest point (x, y) and interaction-zone area (m^2) as the detector defines
    them on exact data. ``detectable`` is False when the detector does not form this group even on exact data
    (members too far apart or zone over its thresholds); interest point and area are NaN then."""

    members: tuple[int, ...]
    interest_point: tuple[float, float]
    area: float
    detectable: bool


def truth_groups(
    people: Sequence[ScenePerson], groups: Sequence[tuple[int, ...]], params: GroupParams | None = None
) -> list[TruthGroup]:
    """The ``groups`` (person ids) among ``people`` with their exact interest points and areas (see the module
    docstring), in the people's frame."""
    params = params or GroupParams()
    by_id = {p.id: p for p in people}
    result = []
    for members in groups:
        found = [
            g for g in detect_groups([by_id[i].as_person() for i in members], params) if set(g.members) == set(members)
        ]
        if found:
            group = found[0]
            point = (float(group.interest_point[0]), float(group.interest_point[1]))
            result.append(TruthGroup(tuple(members), point, float(group.area), True))
        else:
            result.append(TruthGroup(tuple(members), (float("nan"), float("nan")), float("nan"), False))
    return result
