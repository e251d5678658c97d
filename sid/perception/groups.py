"""Conversational groups: records, and detection by one of four methods (``GroupParams.method``).

All coordinates are in the world frame (metres, REP-103, see ``sid.perception.people``); angles in radians.

- ``ospace`` (default): people are assigned to shared o-spaces by minimising a description-length cost
  (``sid.perception.ospace``; docs/groups.md); each group's zone, interest point and spread are then those of the
  paper, computed on its members' rays (``sid.perception.zone``), or the fitted o-space centre when no two members'
  rays meet. With ``GroupParams.positions_only_reach`` set, the people without a facing whom the search leaves
  alone are then grouped by their positions alone (a detector of positions only: a LiDAR leg tracker).
- ``gcff``: the graph-cut detector of Setti et al. 2015 (``sid.perception.gcff``), the literature's reference,
  with one stride and description length for every scene; zones as for ``ospace``.
- ``rays``: the paper's Algorithm 1 with the two additions that ``sid.perception.rays`` describes.
- ``paper``: the literal Algorithm 1, one candidate per DBSCAN cluster (``rays`` with ``meeting_radius=math.inf``).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from sid.checks import MAX_COORDINATE, check_number, check_numbers, check_whole, check_yaw, is_real
from sid.documents import summary
from sid.errors import InputError
from sid.perception.gcff import GCFFParams, gcff_labels
from sid.perception.group import Group
from sid.perception.ospace import TIE, OSpaceModel, find_ospaces
from sid.perception.people import Person
from sid.perception.rays import clustered_groups
from sid.perception.rings import RingModel, joined_rings
from sid.perception.zone import member_crossings, spread, zone_of

__all__ = ["GROUP_METHODS", "GroupParams", "QUANTISED_STEPS", "detect_groups", "facing_step"]

# The facing of a person whose theta is None.
_UNKNOWN_FACING = complex(math.nan, math.nan)

GROUP_METHODS = ("ospace", "gcff", "rays", "paper")


@dataclass(frozen=True)
class GroupParams:
    """Parameters of the group detector (metres, square metres, radians).

    The o-space method's defaults were chosen by leave-one-dataset-out cross-validation over the four F-formation
    benchmarks (``sid eval fformation --cross-validate``, docs/groups.md); the ray methods' come from the geometry
    of conversations, checked one at a time on the benchmarks (docs/parameters.md).

    method: 'ospace' (people assigned to shared o-spaces, the default), 'gcff' (Setti et al.'s graph cuts),
      'rays' (the paper's ray crossings with two additions) or 'paper' (Algorithm 1 as written); the module
      docstring says more, and that of sid.perception.rays for the last two.

    The graph-cut method (``method='gcff'``, ``sid.perception.gcff``):

    gcff_stride: distance (m) ahead of each person at which they vote for the o-space centre. 0.45, the published
      detector's common setting.
    gcff_mdl: description length (m^2) of one o-space and of each person alone. 3.0 (30000 cm^2), the common
      setting.

    The o-space method (``method='ospace'``):

    radius_min: smallest o-space radius R (m), the distance from a member to the group's centre. 0.3: two people
      face to face stand at least 0.6 m apart.
    radius_max: largest o-space radius R (m). 0.8: n people on a circle 0.8-1 m apart have radius
      1 / (2 sin(pi / n)) (0.8-1.0 m at n = 6); chosen by cross-validation among 0.8-1.0 (docs/groups.md).
    radius_steps: proposals per person, at radii evenly spaced over that range. 4: one per 0.2 m.
    group_price: price (m^2) of describing a group: n people form one when their costs and this price sum to less
      than n alone prices. Chosen by cross-validation (docs/groups.md).
    alone_price: price (m^2) of each person left alone, and so the most one member's cost may be. Chosen by
      cross-validation (docs/groups.md).
    facing_slack: half-width (rad) of the cone within which a facing counts as pointing at the centre: facings
      are estimates (a head turned from the body, a tracker's noise). Facings quantised to a few directions get
      half their step if that is wider: a frame whose facings all differ by whole multiples of 90, 45, 30, 22.5 or
      15 degrees is taken as quantised to the largest of these. Chosen by cross-validation (docs/groups.md).
    angular_weight: weight of a member's facing against standing on the circle, 1 being GCFF's proposal distance.
      Chosen by cross-validation (docs/groups.md).
    coarse_pair_reach: in a frame whose facings are quantised coarser than facing_slack (half the step wider
      than it: four or eight directions), two people with known facings at most this far apart (m) also propose
      the o-space of their pair, centred on their midpoint: a quantised facing may point 45 degrees from the
      centre, the proposals ahead then miss it, and proximity carries the decision. 0 turns it off. Chosen by
      cross-validation (docs/groups.md).
    ring_radius_max: arcs found by the o-space search are joined into one group when together they make a ring
      (sid.perception.rings: six or more people on one fitted circle, nobody inside it) of at most this radius
      (m). 2.0: a reception's circle of 12 on 1.6 m with room for noise; 0 turns it off. Not fitted: on the
      benchmarks, whose groups are narrower, every value scores the same (docs/groups.md).
    ring_tolerance: how far (m) a member of a joined ring may stand off its circle. 0.2: a body's depth.
    ring_facing_tolerance: how far (rad) a member's facing may point from a joined ring's centre (or the facings'
      slack when wider). 0.6 (34 degrees): 10 degrees of facing noise stays inside at three standard deviations;
      neighbouring conversations, whose members face their own centres, stay out.
    unknown_facing_cost: a person without facing may join a group when standing on its circle; the unexplained
      facing costs as much as a proposal this far (m) from the centre. 0.5: its square, 0.25 m^2, leaves room under
      the price for standing 0.6 m off the circle; a doubtful facing then gains nothing over a clear one that points
      0.5 m wide.
    unknown_facing_tolerance: a person without facing counts towards opening a group (with at least one member of
      known facing: someone facing a partner half hidden behind them, whose facing the camera cannot tell) only when
      standing within this distance (m) of its circle; farther off they may still join an open one. 0.2, a body's
      depth; chosen by cross-validation on the benchmarks with a share of their facings removed (docs/groups.md).
    positions_only_reach: the reach (m) of groups from positions alone, for a detector that gives no facings (a
      LiDAR leg tracker: set 1.0); 0, the default, turns them off. The people without a facing whom the search
      leaves alone are grouped by the same model, each facing taken as a full cone (any direction costs nothing;
      members stand on the circle), proposals made towards the mean position of the others within this distance
      (the nearest other when nobody is that close), and pairs this close proposing their midpoint. Off by default:
      on the pedestrian sets, strangers waiting side by side become groups (docs/groups.md, "Positions only"); 1.0
      chosen by cross-validation on the F-formation benchmarks with every facing removed.
    positions_only_radius_max: largest o-space radius (m) of a group from positions alone (the smallest is
      radius_min, or this when radius_min is larger). 0.7, chosen with positions_only_reach.
    positions_only_alone_price: price (m^2) of a person without a facing left alone, for groups from positions
      alone (the group price is group_price). 0.8, chosen with positions_only_reach.
    body_radius: a member's line to the centre must pass farther than this (m) from everyone else (the o-space is
      exclusive). Chosen by cross-validation (docs/groups.md).
    facing_weight_floor: the facing weight is floor + (1 - floor) x orientation_quality: a doubtful facing counts
      less, the rest of its cost is that of an unknown facing. 0.5: quality 0 with a theta still counts half. Readers
      of facings without a quality (scenario files, `sid groups` lines, the benchmarks' annotations) give them 1;
      ``Person``'s default quality is 0.

    The ray methods (``method='rays'`` or ``'paper'``):

    eps: DBSCAN neighbourhood radius (m). 2.0: a member of a conversation stands within ~1.5 m of a neighbour, so
      2 m keeps any group in one cluster; clusters only bound the work, the ray geometry splits them.
    min_samples: DBSCAN core size, the person included. 2: a conversation needs two people.
    area_threshold: largest area (m^2) of a group's crossing polygon. 0.5, the authors' value: with facing errors
      of 10-30 degrees the crossings of one conversation scatter over a few tenths of a square metre at most.
    spread_threshold: largest D (m), the mean member distance to the interest point, i.e. the o-space radius.
      1.0: n people ~1 m apart on a circle have radius 1 / (2 sin(pi / n)), 1.0 m for six; Hall's personal
      distance ends at 1.2 m.
    ray_length: length of each facing ray (m). 1.5: it must reach the o-space centre (D <= 1 m) with some slack;
      longer rays mostly add crossings with strangers.
    facing_tolerance: two people whose rays do not cross but who face each other within this angle (rad) meet at
      their midpoint. 0.6 (~34 degrees): face-to-face rays are nearly anti-parallel and miss each other with any
      lateral offset; the tolerance covers facing errors of tens of degrees plus an offset of about half the
      distance between the two.
    meeting_radius: crossings closer than this (m, single linkage) belong to one candidate group; each candidate
      is then pruned as in the paper. 0.6: the crossings of one o-space with facing errors of ~30 degrees scatter
      by ~D tan(30 deg) = 0.6 m. ``math.inf`` makes each DBSCAN cluster one candidate, exactly the paper's
      Algorithm 1, which fails in crowded scenes (``method='paper'`` sets it).
    """

    method: str = "ospace"
    radius_min: float = 0.3
    radius_max: float = 0.8
    radius_steps: int = 4
    group_price: float = 0.8
    alone_price: float = 0.65
    facing_slack: float = 0.4
    angular_weight: float = 0.35
    coarse_pair_reach: float = 1.5
    ring_radius_max: float = 2.0
    ring_tolerance: float = 0.2
    ring_facing_tolerance: float = 0.6
    unknown_facing_cost: float = 0.5
    unknown_facing_tolerance: float = 0.2
    positions_only_reach: float = 0.0
    positions_only_radius_max: float = 0.7
    positions_only_alone_price: float = 0.8
    body_radius: float = 0.1
    facing_weight_floor: float = 0.5
    gcff_stride: float = 0.45
    gcff_mdl: float = 3.0
    eps: float = 2.0
    min_samples: int = 2
    area_threshold: float = 0.5
    spread_threshold: float = 1.0
    ray_length: float = 1.5
    facing_tolerance: float = 0.6
    meeting_radius: float = 0.6

    def __post_init__(self) -> None:
        if self.method not in GROUP_METHODS:
            raise InputError(f"groups: method must be one of {', '.join(GROUP_METHODS)}, got {summary(self.method)}")
        self.ospace_model  # noqa: B018 - builds (and so checks) the o-space fields, once per record
        self.coarse_ospace_model  # noqa: B018 - and the coarse-facing field
        self.positions_only_model  # noqa: B018 - and the positions-only fields
        self.ring_model  # noqa: B018 - and the rings'
        self.gcff_params  # noqa: B018 - likewise the graph-cut fields
        check_number("groups", "facing_weight_floor", self.facing_weight_floor, low=0, low_open=True, high=1)
        check_number("groups", "facing_slack", self.facing_slack, low=0, high=math.pi)
        check_numbers("groups", self, ("eps", "spread_threshold", "ray_length"), low=0, low_open=True, unit="metres")
        check_number("groups", "area_threshold", self.area_threshold, low=0, unit="square metres")
        check_whole("groups", "min_samples", self.min_samples, low=1)
        # math.inf: one candidate per cluster, as in the paper.
        check_number(
            "groups", "meeting_radius", self.meeting_radius, low=0, low_open=True, allow_inf=True, unit="metres"
        )
        right_angle = math.pi / 2
        check_number("groups", "facing_tolerance", self.facing_tolerance, low=0, high=right_angle, high_open=True)

    @cached_property
    def gcff_params(self) -> GCFFParams:
        """The graph-cut method's constants (ValueError naming a bad field); built once per record."""
        try:
            return GCFFParams(stride=self.gcff_stride, mdl=self.gcff_mdl)
        except ValueError as exc:
            raise InputError(str(exc).replace("gcff: ", "groups: gcff_", 1)) from None

    @cached_property
    def ospace_model(self) -> OSpaceModel:
        """The o-space method's constants (ValueError naming a bad field); built once per record."""
        try:
            return OSpaceModel(
                self.radius_min,
                self.radius_max,
                self.radius_steps,
                self.group_price,
                self.unknown_facing_cost,
                self.body_radius,
                self.alone_price,
                self.angular_weight,
                unknown_tolerance=self.unknown_facing_tolerance,
            )
        except ValueError as exc:
            names = {
                "price": "group_price",
                "unknown_cost": "unknown_facing_cost",
                "unknown_tolerance": "unknown_facing_tolerance",
            }
            message = str(exc).replace("ospace: ", "groups: ", 1)
            for old, new in names.items():
                message = message.replace(f"groups: {old} ", f"groups: {new} ", 1)
            raise InputError(message) from None

    @cached_property
    def as_paper(self) -> GroupParams:
        """These parameters with ``meeting_radius`` infinite, as the ``paper`` method runs them; built once per
        record (a record checks all its fields when built)."""
        return replace(self, meeting_radius=math.inf)

    @cached_property
    def ring_model(self) -> RingModel:
        """When the o-space method joins arcs into one wide ring (ValueError naming a bad field)."""
        try:
            return RingModel(self.ring_radius_max, self.ring_tolerance, self.ring_facing_tolerance)
        except ValueError as exc:
            raise InputError(str(exc).replace("rings: ", "groups: ring_", 1)) from None

    @cached_property
    def coarse_ospace_model(self) -> OSpaceModel:
        """``ospace_model`` for a frame with coarse facings: close pairs propose their o-space too."""
        try:
            return replace(self.ospace_model, pair_reach=self.coarse_pair_reach)
        except ValueError as exc:
            raise InputError(str(exc).replace("ospace: pair_reach", "groups: coarse_pair_reach", 1)) from None

    @cached_property
    def positions_only_model(self) -> OSpaceModel:
        """``ospace_model`` for the people without a facing left alone, grouped by their positions only."""
        # ospace_model checked the fields it shares; radius_min can only fail here as min(radius_min, radius_max)
        names = {
            "pair_reach": "reach",
            "radius_min": "radius_max",
            "radius_max": "radius_max",
            "alone_price": "alone_price",
        }
        try:
            return replace(
                self.ospace_model,
                pair_reach=self.positions_only_reach,
                radius_min=min(self.radius_min, self.positions_only_radius_max),  # a radius_min above it: one radius
                radius_max=self.positions_only_radius_max,
                alone_price=self.positions_only_alone_price,
            )
        except ValueError as exc:
            message = str(exc)
            for old, new in names.items():
                message = message.replace(f"ospace: {old} ", f"groups: positions_only_{new} ", 1)
            raise InputError(message.replace("ospace: ", "groups: ", 1)) from None


def detect_groups(people: Sequence[Person], params: GroupParams = GroupParams()) -> list[Group]:
    """Interacting groups among ``people`` (world frame) by ``params.method``.

    Members are listed in input order, groups in order of their first member. Every method sees the people sorted
    by id, so that the same people in another order give the same groups. Raises ValueError naming the person for a
    non-finite position or yaw, and for duplicate ids. Fewer than two people give no group.
    """
    people = list(people)
    ids, positions, facing = _validated(people)
    if len(people) < 2:
        return []
    if params.method == "ospace":
        return _ospace_groups(people, ids, positions, facing, params)
    if params.method == "gcff":
        return _gcff_groups(people, ids, positions, facing, params)
    if params.method == "paper" and not math.isinf(params.meeting_radius):
        params = params.as_paper
    return clustered_groups(ids, positions, facing, params)


def _ospace_groups(
    people: list[Person], ids: list[int], positions: list[complex], facing: list[complex], params: GroupParams
) -> list[Group]:
    """The o-space method's groups, each with the paper's zone geometry on its members' rays (see the module
    docstring), or the fitted o-space centre when no two members' rays meet. On Python numbers: a frame's groups
    have a handful of members, for which numpy's overhead per call outweighs the work.

    The search sees the people sorted by id, their positions measured from their mean, and breaks ties by that
    order: the same people, permuted, moved or turned, give the same groups."""
    floor = params.facing_weight_floor
    order = sorted(range(len(people)), key=ids.__getitem__)
    origin = complex(math.fsum(positions[i].real for i in order), math.fsum(positions[i].imag for i in order))
    origin /= len(order)
    thetas = [people[i].theta for i in order]
    half_step = 0.5 * facing_step(thetas)  # rad
    coarse = half_step > params.facing_slack  # quantised more coarsely than the facings' own slack
    slack = max(params.facing_slack, half_step)  # rad, every facing's cone
    seen = [positions[i] - origin for i in order]
    seen_facing = [facing[i] for i in order]
    found = find_ospaces(
        seen,
        seen_facing,
        [floor + (1.0 - floor) * min(max(people[i].orientation_quality, 0.0), 1.0) for i in order],
        params.coarse_ospace_model if coarse else params.ospace_model,
        [slack] * len(order),
    )
    joined, joined_centres = joined_rings(
        [ospace.members.tolist() for ospace in found],
        [ospace.centre for ospace in found],
        seen,
        seen_facing,
        slack,
        params.ring_model,
    )
    unfaced, unfaced_centres = _positions_only(seen, seen_facing, {k for g in joined for k in g}, params)
    joined, joined_centres = joined + unfaced, joined_centres + unfaced_centres
    members = [sorted(order[k] for k in group) for group in joined]
    centres = [centre + origin for centre in joined_centres]
    ranked = sorted(range(len(members)), key=lambda g: members[g][0])  # groups in order of their first member
    return _zoned([members[g] for g in ranked], [centres[g] for g in ranked], ids, positions, facing, params)


def _positions_only(
    positions: list[complex], facing: list[complex], grouped: set[int], params: GroupParams
) -> tuple[list[list[int]], list[complex]]:
    """Groups (indices, ascending) and their centres (the members' mean, complex m) among the people of unknown
    ``facing`` (NaN) not in ``grouped``, from their ``positions`` (complex, m) only (``GroupParams``'
    ``positions_only_reach`` and the two fields after it). Every comparison as the o-space search's, within ``TIE``:
    the same people moved, turned or permuted give the same groups."""
    if params.positions_only_reach <= 0:
        return [], []
    left = [k for k, f in enumerate(facing) if f != f and k not in grouped]
    if len(left) < 2:
        return [], []
    placed = [positions[k] for k in left]
    toward = _towards_neighbours(np.array([(p.real, p.imag) for p in placed]), params.positions_only_reach)
    cone = [math.pi] * len(left)  # any direction: only standing on the circle costs
    found = find_ospaces(placed, toward, [1.0] * len(left), params.positions_only_model, cone)
    joined, _ = joined_rings(
        [ospace.members.tolist() for ospace in found],
        [ospace.centre for ospace in found],
        placed,
        toward,
        math.pi,
        params.ring_model,
    )
    members = [[left[k] for k in group] for group in joined]
    # The centre: the members' mean, which no facing can pull (the search's fit stops when the members settle).
    centres = [
        complex(math.fsum(positions[k].real for k in group), math.fsum(positions[k].imag for k in group)) / len(group)
        for group in members
    ]
    return members, centres


def _towards_neighbours(xy: np.ndarray, reach: float) -> list[complex]:
    """Per person at ``xy`` ((N, 2), m, N >= 2), the unit direction (complex) to the mean position of the others
    within ``reach`` (m), or to the nearest other (lowest index among the equally near) when nobody is, or when that
    mean is the person's own position; 1 when everyone stands on one spot. Distances within ``TIE`` count as
    equal."""
    offsets = xy[None, :, :] - xy[:, None, :]  # [a, b]: from a to b
    distance2 = np.einsum("abk,abk->ab", offsets, offsets)
    np.fill_diagonal(distance2, np.inf)
    within = distance2 <= reach * reach * (1.0 + TIE)
    counts = within.sum(axis=1)
    towards = np.einsum("ab,abk->ak", within, offsets) / np.maximum(counts, 1)[:, None]
    apart = np.where(distance2 > 0, distance2, np.inf)  # the others, those on the person's own spot left out
    nearest = apart.min(axis=1)
    scale = np.sqrt(np.where(np.isfinite(nearest), nearest, 1.0))
    lost = (counts == 0) | (np.hypot(towards[:, 0], towards[:, 1]) <= TIE * scale)
    for a in np.flatnonzero(lost).tolist():
        if math.isfinite(nearest[a]):
            b = int(np.flatnonzero(apart[a] <= nearest[a] * (1.0 + TIE))[0])
            towards[a] = offsets[a, b]
        else:  # everyone on this person's spot
            towards[a] = (1.0, 0.0)
    return [complex(x, y) / math.hypot(x, y) for x, y in towards.tolist()]


def _gcff_groups(
    people: list[Person], ids: list[int], positions: list[complex], facing: list[complex], params: GroupParams
) -> list[Group]:
    """The graph-cut method's groups, with the o-space method's zones; a group whose members' rays do not meet
    gets the mean of its members' votes (position + stride x facing, known facings only) as its centre. The graph
    cuts see the people sorted by id: their moves break exact ties by index."""
    order = sorted(range(len(people)), key=ids.__getitem__)
    labels = gcff_labels(
        np.array([(positions[i].real, positions[i].imag) for i in order]),
        np.array([math.nan if people[i].theta is None else people[i].theta for i in order]),
        params.gcff_params,
    ).tolist()
    found: dict[int, list[int]] = {}
    for k, label in zip(order, labels, strict=True):
        if label >= 0:  # -1: alone
            found.setdefault(label, []).append(k)
    members = sorted(sorted(group) for group in found.values())  # input order, groups by their first member
    stride = params.gcff_stride
    votes = [[positions[j] + stride * facing[j] for j in group if facing[j] == facing[j]] for group in members]
    centres = [sum(v, 0j) / len(v) for v in votes]
    return _zoned(members, centres, ids, positions, facing, params)


def _zoned(
    members: list[list[int]],
    centres: list[complex],
    ids: list[int],
    positions: list[complex],
    facing: list[complex],
    params: GroupParams,
) -> list[Group]:
    """Groups of the given members (indices, ascending) with the paper's zone geometry on their rays (module
    docstring), or ``centres`` (complex, m) where no two members' rays meet."""
    groups = []
    for fallback, group, crossings in zip(
        centres, members, member_crossings(positions, facing, members, params), strict=True
    ):
        if crossings:
            area, centre, zone = zone_of(crossings)
        else:  # no two members' rays meet: the centre given (fitted o-space, or mean vote)
            area, centre = 0.0, fallback
            zone = np.array([[centre.real, centre.imag]])
        groups.append(
            Group(
                members=tuple(ids[i] for i in group),
                interest_point=(centre.real, centre.imag),
                area=area,
                zone=zone,
                spread=spread([positions[i] for i in group], centre),
            )
        )
    return groups


QUANTISED_STEPS = tuple(math.radians(d) for d in (90.0, 45.0, 30.0, 22.5, 15.0))
"""Steps (rad) of the facing quantisations ``facing_step`` recognises, coarsest first."""
_STEP_RESIDUAL = 1e-3  # rad: a difference of facings this close to a whole number of steps is one


def facing_step(thetas: Sequence[float | None]) -> float:
    """The step (rad) to which the known facings among ``thetas`` (yaws, rad) are quantised: the coarsest of
    ``QUANTISED_STEPS`` of which every difference between two of them is a whole multiple, or 0 (continuous
    facings, or fewer than two known). Differences, not the yaws themselves: turning the scene keeps the step. Each
    yaw is first taken to [-pi, pi] (a whole turn is a multiple of every step), so that any finite yaw, 1e308 too,
    gives a finite difference."""
    known = [math.remainder(t, math.tau) for t in thetas if t is not None]
    if len(known) < 2:
        return 0.0
    reference = known[0]
    for step in QUANTISED_STEPS:
        if all(abs(d - step * round(d / step)) <= _STEP_RESIDUAL for d in (t - reference for t in known[1:])):
            return step
    return 0.0


def _validated(people: list[Person]) -> tuple[list[int], list[complex], list[complex]]:
    """Ids, positions and unit facing vectors as complex numbers x + iy (NaN facing = unknown), validated."""
    ids = [p.id for p in people]
    for i in ids:  # before sorting by id, which would fail inside Python on a str or None
        if type(i) is not int and (isinstance(i, bool) or not isinstance(i, numbers.Integral)):
            raise InputError(f"groups: person id {i!r} is not a whole number")
    if len(set(ids)) != len(ids):
        duplicates = sorted({i for i in ids if ids.count(i) > 1})
        raise InputError(f"groups: person ids must be unique, repeated: {duplicates}")
    positions = []
    facing = []
    for person in people:
        if not (is_real(person.x) and is_real(person.y)):
            raise InputError(
                f"groups: person {person.id} has a position that is not a pair of numbers: ({person.x!r}, {person.y!r})"
            )
        if not (math.isfinite(person.x) and math.isfinite(person.y)):
            raise InputError(f"groups: person {person.id} has a non-finite position ({person.x}, {person.y})")
        quality = person.orientation_quality
        if not (is_real(quality) and math.isfinite(quality)):
            raise InputError(
                f"groups: person {person.id} has orientation_quality {quality!r}: a finite number is needed (values "
                "outside [0, 1] count as the nearer end)"
            )
        if max(abs(person.x), abs(person.y)) > MAX_COORDINATE:
            raise InputError(
                f"groups: person {person.id} at ({person.x}, {person.y}) is farther than {MAX_COORDINATE:g} m from "
                "the frame's origin along x or y"
            )
        positions.append(complex(person.x, person.y))
        if person.theta is None:
            facing.append(_UNKNOWN_FACING)
        elif not is_real(person.theta):
            raise InputError(
                f"groups: person {person.id} has a theta that is not a number: {person.theta!r} (use None)"
            )
        elif not math.isfinite(person.theta):
            raise InputError(f"groups: person {person.id} has a non-finite theta {person.theta} (use None)")
        else:
            check_yaw(f"groups: person {person.id}", "theta", person.theta)
            facing.append(complex(math.cos(person.theta), math.sin(person.theta)))
    return ids, positions, facing
