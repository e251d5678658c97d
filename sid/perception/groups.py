"""Conversational groups: records, and detection by one of four methods (``GroupParams.method``).

All coordinates are in the world frame (metres, REP-103, see ``sid.perception.people``); angles in radians.

- ``ospace`` (default): people are assigned to shared o-spaces by minimising a description-length cost
  (``sid.perception.ospace``; docs/groups.md); each group's zone, interest point and spread are then those of the
  paper (below), computed on its members' rays, or the fitted o-space centre when no two members' rays meet.
- ``gcff``: the graph-cut detector of Setti et al. 2015 (``sid.perception.gcff``), the literature's reference,
  with one stride and description length for every scene; zones as for ``ospace``.
- ``rays``: the paper's Algorithm 1 with the two additions described below.
- ``paper``: the literal Algorithm 1, one candidate per DBSCAN cluster (``rays`` with ``meeting_radius=math.inf``).

The ray method. Per frame: DBSCAN on the people's positions; per cluster, each person with a known facing casts a
ray (a segment of ``ray_length``) from their position along their facing; where two rays cross, the two people
look at a common point. The convex hull of the crossings is the interaction zone (area A, centroid = interest
point), and D is the mean distance of the members to the interest point. While A or D exceed their thresholds, the
member whose removal helps most is dropped; a cluster that ends under both thresholds is a group.

Choices the paper leaves open, decided here:
- People with unknown facing (theta None) count in DBSCAN (they are there, and link neighbours) but cast no ray,
  so they are never members: a ray is the only evidence of taking part in a conversation.
- A member whose ray meets no other member's ray is dropped before the geometry (it contributes no crossing, so
  it could only pass the thresholds by standing close, e.g. someone just behind a group facing away).
- Two people facing each other: their rays are (nearly) anti-parallel and often miss each other (parallel, or
  crossing behind one of them), and where they do cross, at a shallow angle, the crossing lies anywhere between
  the two (on one of them when the other looks straight at them) and follows every degree of facing noise. So
  when each faces the other within ``facing_tolerance`` and their rays are within 20 degrees of anti-parallel, the
  pair meets at the midpoint between them, crossing or not; a steeper crossing is kept (a face-to-face pair both
  turned towards one side looks at a spot beside the line between them).
- The polygon is the convex hull of the crossings (as the authors' code does), vertices counter-clockwise; area
  and centroid by the shoelace formula. When the hull is degenerate (one crossing, coinciding or
  collinear crossings; area below 1e-9 m^2) the area is 0 and the interest point is the mean of the crossings.
- Pruning removes, at each step, the member whose removal minimises max(A / A_thr, D / D_thr); it stops with no
  group when no removal lowers that value or fewer than two members would remain.
- A DBSCAN cluster may hold several conversations side by side (a coffee break), and pruning one big set of
  people member by member then fails. So the crossings of a cluster are first grouped by proximity
  (``meeting_radius``, single linkage); the people whose rays meet at one spot form a candidate, candidates are
  pruned in order of their number of crossings (most first), and a person joins at most one group. With one
  spot (any single conversation) this is exactly the paper's algorithm; ``meeting_radius=math.inf`` forces it.
"""

from __future__ import annotations

import itertools
import math
import operator
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import cached_property, lru_cache

import numpy as np

from sid.checks import MAX_COORDINATE, check_number, check_numbers, check_whole, is_real
from sid.documents import summary
from sid.perception.cluster import dbscan_labels
from sid.perception.gcff import GCFFParams, gcff_labels
from sid.perception.group import Group
from sid.perception.ospace import OSpaceModel, find_ospaces
from sid.perception.people import Person
from sid.perception.rings import RingModel, joined_rings

__all__ = ["GROUP_METHODS", "GroupParams", "QUANTISED_STEPS", "detect_groups", "facing_step"]

# |sin| of the angle between two rays below which they count as parallel (their crossing is rounding noise).
_PARALLEL = 1e-9
# |sin| of the angle between the rays of a face-to-face pair below which they meet at their midpoint, crossing or
# not (module docstring): 20 degrees from anti-parallel. There a crossing moves ~2 cm per degree of facing noise for
# people 0.8 m apart (~1 cm at 34 degrees), and the switch to the midpoint moves the point by at most 7 cm.
_SHALLOW = math.sin(math.radians(20.0))
# Relative difference below which two removals' excess values tie (rounding, e.g. after moving the scene).
_TIE = 1e-9
# Hull area (m^2) below which the polygon of crossings is treated as degenerate (a point or a segment).
_DEGENERATE_AREA = 1e-9
# Sort key of a point x + iy: (x, y).
_BY_X_THEN_Y = operator.attrgetter("real", "imag")
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
      docstring says more.

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
            raise ValueError(f"groups: method must be one of {', '.join(GROUP_METHODS)}, got {summary(self.method)}")
        self.ospace_model  # noqa: B018 - builds (and so checks) the o-space fields, once per record
        self.coarse_ospace_model  # noqa: B018 - and the coarse-facing field
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
            raise ValueError(str(exc).replace("gcff: ", "groups: gcff_", 1)) from None

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
            raise ValueError(message) from None

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
            raise ValueError(str(exc).replace("rings: ", "groups: ring_", 1)) from None

    @cached_property
    def coarse_ospace_model(self) -> OSpaceModel:
        """``ospace_model`` for a frame with coarse facings: close pairs propose their o-space too."""
        try:
            return replace(self.ospace_model, pair_reach=self.coarse_pair_reach)
        except ValueError as exc:
            raise ValueError(str(exc).replace("ospace: pair_reach", "groups: coarse_pair_reach", 1)) from None


@dataclass(frozen=True)
class _Geometry:
    """Area (m^2), centre (complex x + iy), (K, 2) zone and spread D (m) of a candidate's crossings."""

    area: float
    centre: complex
    zone: np.ndarray
    spread: float

    def excess(self, params: GroupParams) -> float:
        """max(A / A_thr, D / D_thr): <= 1 when both are under their thresholds."""
        area_ratio = self.area / params.area_threshold if params.area_threshold > 0 else (math.inf if self.area else 0)
        return max(area_ratio, self.spread / params.spread_threshold)


def detect_groups(people: Sequence[Person], params: GroupParams = GroupParams()) -> list[Group]:
    """Interacting groups among ``people`` (world frame) by ``params.method``.

    Members are listed in input order, groups in order of their first member. Every method but ``gcff`` sees the
    people sorted by id, so that the same people in another order give the same groups. Raises ValueError naming
    the person for a non-finite position or yaw, and for duplicate ids. Fewer than two people give no group.
    """
    people = list(people)
    ids, positions, facing = _validated(people)
    if len(people) < 2:
        return []
    if params.method == "ospace":
        return _ospace_groups(people, ids, positions, facing, params)
    if params.method == "gcff":
        return _gcff_groups(people, positions, facing, params)
    if params.method == "paper" and not math.isinf(params.meeting_radius):
        params = params.as_paper
    return _clustered_groups(ids, positions, facing, params)


def _clustered_groups(
    ids: list[int], positions: list[complex], facing: list[complex], params: GroupParams
) -> list[Group]:
    """The ``rays`` and ``paper`` methods' groups: DBSCAN clusters of the people sorted by id (DBSCAN numbers its
    clusters, and the pruning breaks its ties, in the order it is given), each pruned to its groups; members and
    groups then listed in input order."""
    order = sorted(range(len(ids)), key=ids.__getitem__)
    position_array = np.array([positions[i] for i in order], dtype=complex)
    facing_array = np.array([facing[i] for i in order], dtype=complex)
    labels = dbscan_labels(np.column_stack((position_array.real, position_array.imag)), params.eps, params.min_samples)
    has_ray = ~np.isnan(facing_array)
    groups: list[Group] = []
    for label in range(int(labels.max()) + 1):
        cluster = np.flatnonzero((labels == label) & has_ray)
        if len(cluster) >= 2:
            groups.extend(
                _groups_in_cluster(
                    [ids[order[i]] for i in cluster], position_array[cluster], facing_array[cluster], params
                )
            )
    index = {person: k for k, person in enumerate(ids)}
    for group in groups:
        group.members = tuple(sorted(group.members, key=index.__getitem__))
    return sorted(groups, key=lambda group: index[group.members[0]])


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
    members = [sorted(order[k] for k in group) for group in joined]
    centres = [centre + origin for centre in joined_centres]
    ranked = sorted(range(len(members)), key=lambda g: members[g][0])  # groups in order of their first member
    return _zoned([members[g] for g in ranked], [centres[g] for g in ranked], ids, positions, facing, params)


def _gcff_groups(
    people: list[Person], positions: list[complex], facing: list[complex], params: GroupParams
) -> list[Group]:
    """The graph-cut method's groups, with the o-space method's zones; a group whose members' rays do not meet
    gets the mean of its members' votes (position + stride x facing, known facings only) as its centre."""
    labels = gcff_labels(
        np.array([(p.real, p.imag) for p in positions]),
        np.array([math.nan if p.theta is None else p.theta for p in people]),
        params.gcff_params,
    ).tolist()
    members = [[j for j, label in enumerate(labels) if label == g] for g in range(max(labels, default=-1) + 1)]
    stride = params.gcff_stride
    votes = [[positions[j] + stride * facing[j] for j in group if facing[j] == facing[j]] for group in members]
    centres = [sum(v, 0j) / len(v) for v in votes]
    return _zoned(members, centres, [p.id for p in people], positions, facing, params)


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
        centres, members, _member_crossings(positions, facing, members, params), strict=True
    ):
        if crossings:
            area, centre, zone = _zone(crossings)
        else:  # no two members' rays meet: the centre given (fitted o-space, or mean vote)
            area, centre = 0.0, fallback
            zone = np.array([[centre.real, centre.imag]])
        groups.append(
            Group(
                members=tuple(ids[i] for i in group),
                interest_point=(centre.real, centre.imag),
                area=area,
                zone=zone,
                spread=_spread([positions[i] for i in group], centre),
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
    if len(set(ids)) != len(ids):
        duplicates = sorted({i for i in ids if ids.count(i) > 1})
        raise ValueError(f"groups: person ids must be unique, repeated: {duplicates}")
    positions = []
    facing = []
    for person in people:
        if not (is_real(person.x) and is_real(person.y)):
            raise ValueError(
                f"groups: person {person.id} has a position that is not a pair of numbers: ({person.x!r}, {person.y!r})"
            )
        if not (math.isfinite(person.x) and math.isfinite(person.y)):
            raise ValueError(f"groups: person {person.id} has a non-finite position ({person.x}, {person.y})")
        quality = person.orientation_quality
        if not (is_real(quality) and math.isfinite(quality)):
            raise ValueError(
                f"groups: person {person.id} has orientation_quality {quality!r}: a finite number is needed (values "
                "outside [0, 1] count as the nearer end)"
            )
        if max(abs(person.x), abs(person.y)) > MAX_COORDINATE:
            raise ValueError(
                f"groups: person {person.id} at ({person.x}, {person.y}) is farther than {MAX_COORDINATE:g} m from "
                "the frame's origin along x or y"
            )
        positions.append(complex(person.x, person.y))
        if person.theta is None:
            facing.append(_UNKNOWN_FACING)
        elif not is_real(person.theta):
            raise ValueError(
                f"groups: person {person.id} has a theta that is not a number: {person.theta!r} (use None)"
            )
        elif not math.isfinite(person.theta):
            raise ValueError(f"groups: person {person.id} has a non-finite theta {person.theta} (use None)")
        else:
            facing.append(complex(math.cos(person.theta), math.sin(person.theta)))
    return ids, positions, facing


@dataclass(frozen=True)
class _Meetings:
    """Pairs of people (indices into the cluster) whose rays meet, and where (complex x + iy)."""

    first: np.ndarray
    second: np.ndarray
    points: np.ndarray


@lru_cache(maxsize=64)
def _pairs(k: int) -> tuple[np.ndarray, np.ndarray]:
    return np.triu_indices(k, 1)


def _ray_meetings(
    positions: np.ndarray,
    facing: np.ndarray,
    params: GroupParams,
    pairs: tuple[np.ndarray, np.ndarray] | None = None,
) -> _Meetings:
    """Where the rays of each pair (all pairs unless given, i < j) meet (see the module docstring); positions and
    facings are complex numbers x + iy. Dot and cross products are written out on the real parts: numpy's complex
    products fuse multiply-adds on some CPUs, which would make the last bits depend on the machine and differ from
    ``_member_crossings``' Python arithmetic."""
    i, j = _pairs(len(positions)) if pairs is None else pairs
    pi, pj, fi, fj = positions[i], positions[j], facing[i], facing[j]
    d = pj - pi
    dx, dy, fix, fiy, fjx, fjy = d.real, d.imag, fi.real, fi.imag, fj.real, fj.imag
    # Rays p_i + s f_i and p_j + t f_j meet where s f_i - t f_j = d = p_j - p_i: s = cross(d, f_j) / cross(f_i, f_j)
    # and t = cross(d, f_i) / cross(f_i, f_j); the segments meet when both lie in [0, ray_length].
    denom = fix * fjy - fiy * fjx
    half = 0.5 * params.ray_length
    distance = np.abs(d)
    # Face to face: each looks at the other within the tolerance (dot(f, d) >= cos(tol) |d|).
    reach = math.cos(params.facing_tolerance) * distance
    facing_j = dx * fix + dy * fiy >= reach
    facing_i = -(dx * fjx + dy * fjy) >= reach
    face_to_face = facing_j & facing_i & (distance > 0) & (distance <= 4 * half)
    # A denominator next to 0 (facings parallel to within ~1e-300) overflows s and t to inf; such pairs are not
    # crossings (|denom| <= _PARALLEL) and take the midpoint, so the inf is never used.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = (dx * fjy - dy * fjx) / denom
        t = (dx * fiy - dy * fix) / denom
        crossing = (np.abs(denom) > _PARALLEL) & (np.maximum(np.abs(s - half), np.abs(t - half)) <= half)
        # A face-to-face pair whose rays are nearly anti-parallel meets at its midpoint, whether or not they cross.
        points = np.where(crossing & ~(face_to_face & (np.abs(denom) < _SHALLOW)), pi + s * fi, 0.5 * (pi + pj))
    meet = crossing | face_to_face
    return _Meetings(i[meet], j[meet], points[meet])


def _member_crossings(
    positions: list[complex], facing: list[complex], groups: list[list[int]], params: GroupParams
) -> list[list[complex]]:
    """Per group (member indices into ``positions``), where its members' rays meet, pair by pair in the order of
    ``itertools.combinations``: ``_ray_meetings`` on Python numbers, for the o-space method's few members (numpy's
    overhead per call outweighs the work). The same operations in the same order, so the same bits; a test checks
    it."""
    half = 0.5 * params.ray_length
    cos_tolerance = math.cos(params.facing_tolerance)
    crossings: list[list[complex]] = []
    for group in groups:
        found: list[complex] = []
        for i, j in itertools.combinations(group, 2):
            pi, fi, fj = positions[i], facing[i], facing[j]
            d = positions[j] - pi
            dx, dy, fix, fiy, fjx, fjy = d.real, d.imag, fi.real, fi.imag, fj.real, fj.imag
            distance = abs(d)
            reach = cos_tolerance * distance
            face_to_face = dx * fix + dy * fiy >= reach and -(dx * fjx + dy * fjy) >= reach and 0 < distance <= 4 * half
            denom = fix * fjy - fiy * fjx
            if abs(denom) > _PARALLEL and not (face_to_face and abs(denom) < _SHALLOW):
                s, t = (dx * fjy - dy * fjx) / denom, (dx * fiy - dy * fix) / denom
                if max(abs(s - half), abs(t - half)) <= half:
                    found.append(pi + s * fi)
                    continue
            if face_to_face:
                found.append(0.5 * (pi + positions[j]))
        crossings.append(found)
    return crossings


def _groups_in_cluster(ids: list[int], positions: np.ndarray, facing: np.ndarray, params: GroupParams) -> list[Group]:
    meetings = _ray_meetings(positions, facing, params)
    points = meetings.points
    if len(points) == 0:
        return []
    if math.isinf(params.meeting_radius) or np.abs(points[:, None] - points[None, :]).max() <= params.meeting_radius:
        candidates = [np.ones(len(ids), dtype=bool)]  # all crossings within reach of each other: one spot
    else:
        spots = dbscan_labels(np.column_stack((points.real, points.imag)), params.meeting_radius, 1)
        # Candidates in order of their number of crossings, most first (ties: in order of discovery).
        order = sorted(range(int(spots.max()) + 1), key=lambda spot: -np.count_nonzero(spots == spot))
        candidates = []
        for spot in order:
            mask = np.zeros(len(ids), dtype=bool)
            mask[meetings.first[spots == spot]] = True
            mask[meetings.second[spots == spot]] = True
            candidates.append(mask)
    remaining = np.ones(len(ids), dtype=bool)
    groups = []
    for mask in candidates:
        found = _prune(mask & remaining, meetings, positions, ids, params)
        if found is None:
            continue
        members, geometry = found
        groups.append(
            Group(
                members=tuple(ids[i] for i in np.flatnonzero(members)),
                interest_point=(geometry.centre.real, geometry.centre.imag),
                area=geometry.area,
                zone=geometry.zone,
                spread=geometry.spread,
            )
        )
        remaining &= ~members
    return groups


def _active(members: np.ndarray, meetings: _Meetings) -> np.ndarray:
    """Which meetings are between two members."""
    return members[meetings.first] & members[meetings.second]


def _with_meetings(members: np.ndarray, meetings: _Meetings) -> np.ndarray:
    """The members whose ray meets another member's ray."""
    active = _active(members, meetings)
    result = np.zeros_like(members)
    result[meetings.first[active]] = True
    result[meetings.second[active]] = True
    return result


def _geometry(members: np.ndarray, meetings: _Meetings, positions: np.ndarray) -> _Geometry:
    """The zone of the crossings between ``members`` (bool mask)."""
    area, centre, zone = _zone(meetings.points[_active(members, meetings)].tolist())
    return _Geometry(area, centre, zone, _spread(positions[members].tolist(), centre))


def _zone(crossings: list[complex]) -> tuple[float, complex, np.ndarray]:
    """Hull area (m^2), centre (complex x + iy, m) and (K, 2) zone polygon of ``crossings`` (at least one)."""
    hull = _convex_hull(crossings) if len(crossings) >= 3 else []
    area, centre = _shoelace(hull) if len(hull) >= 3 else (0.0, 0j)
    if area > _DEGENERATE_AREA:
        return area, centre, np.array([(p.real, p.imag) for p in hull])
    centre, zone = _degenerate_zone(crossings)
    return 0.0, centre, zone


def _spread(member_positions: list[complex], centre: complex) -> float:
    """D (m): the mean distance of the members to ``centre``, the distances summed exactly (``math.fsum``), so
    that the value depends neither on the members' order nor on the machine."""
    return math.fsum([abs(p - centre) for p in member_positions]) / len(member_positions)


def _convex_hull(points: list[complex]) -> list[complex]:
    """Counter-clockwise convex hull (Andrew's monotone chain), collinear points dropped.

    Hand-written rather than shapely's: the pruning loop builds several hulls of a handful of points per call, where
    a shapely round trip costs several times more (docs/parameters.md).
    """
    ordered = sorted(set(points), key=_BY_X_THEN_Y)
    if len(ordered) < 3:
        return ordered

    def chain(sequence: list[complex]) -> list[complex]:
        kept: list[complex] = []
        for p in sequence:
            while len(kept) >= 2 and ((kept[-1] - kept[-2]).conjugate() * (p - kept[-2])).imag <= 0:
                kept.pop()
            kept.append(p)
        return kept[:-1]

    return chain(ordered) + chain(ordered[::-1])


def _shoelace(polygon: list[complex]) -> tuple[float, complex]:
    """Area and centroid of a counter-clockwise polygon (shoelace formula); the centroid is 0 for zero area.

    Computed relative to the first vertex, so a thin polygon far from the origin keeps its precision (the products
    of absolute coordinates would cancel).
    """
    origin = polygon[0]
    local = [p - origin for p in polygon]
    twice_area = 0.0
    moment = 0j
    for a, b in zip(local, local[1:] + local[:1], strict=True):
        cross = (a.conjugate() * b).imag
        twice_area += cross
        moment += cross * (a + b)
    if twice_area <= 0:
        return 0.0, 0j
    return 0.5 * twice_area, origin + moment / (3.0 * twice_area)


def _degenerate_zone(crossings: list[complex]) -> tuple[complex, np.ndarray]:
    """Centre (the mean) and (K, 2) zone of crossings whose hull has no area: the centre when the crossings
    coincide, else the two extreme crossings."""
    if len(crossings) == 1:
        return crossings[0], np.array([[crossings[0].real, crossings[0].imag]])
    points = np.array(crossings)
    centre = complex(points.sum() / len(points))
    offsets = points - centre
    far = offsets[int(np.argmax(np.abs(offsets)))]
    if abs(far) < 1e-6:
        ends = np.array([centre])
    else:
        along = (offsets * far.conjugate()).real
        ends = points[[int(np.argmin(along)), int(np.argmax(along))]]
    return centre, np.column_stack((ends.real, ends.imag))


def _prune(
    candidates: np.ndarray, meetings: _Meetings, positions: np.ndarray, ids: list[int], params: GroupParams
) -> tuple[np.ndarray, _Geometry] | None:
    """The group left after pruning ``candidates`` (bool mask), with its geometry, or None.

    Removals whose excess ties (within rounding: moving the scene must not change the choice) go to the lowest
    person id, so that neither the input order nor the scene's placement decides between them."""
    members = _with_meetings(candidates, meetings)
    if np.count_nonzero(members) < 2:
        return None
    geometry = _geometry(members, meetings, positions)
    excess = geometry.excess(params)
    while excess > 1.0:
        best: tuple[float, np.ndarray, _Geometry, int] | None = None
        for i in np.flatnonzero(members):
            trial = members.copy()
            trial[i] = False
            trial = _with_meetings(trial, meetings)
            if np.count_nonzero(trial) < 2:
                continue
            trial_geometry = _geometry(trial, meetings, positions)
            trial_excess = trial_geometry.excess(params)
            if best is None or trial_excess < best[0] - _TIE * max(1.0, best[0]):
                best = (trial_excess, trial, trial_geometry, ids[i])
            elif trial_excess <= best[0] + _TIE * max(1.0, best[0]) and ids[i] < best[3]:
                best = (min(trial_excess, best[0]), trial, trial_geometry, ids[i])
        if best is None or best[0] >= excess:
            return None
        excess, members, geometry, _ = best
    return members, geometry
