"""O-space assignment: which people share a conversational o-space, and where its centre lies (world frame, metres).

The model (after the F-formation literature: Setti et al.'s graph-cut detector, PLoS One 2015; written here from
its description, no code taken). An o-space is a circle (centre c, radius R) that its members stand on and face.
Person j at p_j, rho_j = |c - p_j| from the centre, whose unit facing f_j turns phi_j away from the direction to
the centre, joins o-space (c, R) at a cost (m^2) of

    known facing:    e_j = (rho_j - R)^2 + a 2 R rho_j (1 - cos(max(0, phi_j - s_j)))
    unknown facing:  u_j = (rho_j - R)^2 + unknown_cost^2           (stands on the circle, facing unexplained)
    doubtful facing: w_j e_j + (1 - w_j) u_j, w_j the facing weight in [0, 1]

With a = 1 and s_j = 0, e_j is |p_j + R f_j - c|^2, the squared distance of the centre from the person's
*proposal* p_j + R f_j (GCFF's vote). s_j, the facing's slack (rad), widens the facing into a cone: a facing known
only to within s_j costs nothing while the centre lies inside the cone (quantised facings, a head turned from the
body); a (``angular_weight``) weighs the facing against standing on the circle.

Each o-space is charged a price (m^2) for being described, and every person left alone another (``alone_price``),
so that two people form a group when their two costs and the group's price sum to less than two people alone (a
minimum-description-length choice). A member whose straight line to the centre passes within ``body_radius`` of
another person is refused: the o-space is exclusive, nobody stands between a member and the centre.

Unlike a fixed stride, each o-space takes its own radius from the data: given its members and each member's
facing turned into its cone towards the centre (f'_j), the c and R that minimise the weighted sum of
|p_j + R f'_j - c|^2 are closed-form (c = mean proposal, R a one-dimensional least squares, clamped to
[radius_min, radius_max]). The search alternates two steps until the partition is stable:

1. assignment: candidate o-spaces are opened greedily by largest saving (the standard greedy heuristic for this
   uncapacitated facility-location problem), each person then takes the cheapest open o-space or stays alone;
2. refit: each group's c and R from its members.

The first candidates are every known-facing person's proposals at several radii (``radius_min`` to ``radius_max``)
and, for two known facings within ``pair_reach`` of each other, neither facing more than 90 degrees away from the
other, the o-space of their pair (centre their midpoint, radius half their distance): where facings are coarse the
proposals ahead miss the centre, and proximity has to carry the decision. Later rounds use the refitted groups plus
the first proposals of whoever is still alone. An o-space opens when it lowers the cost of two people or more, one
at least with a known facing; a person of unknown facing counts towards that only when standing within
``unknown_tolerance`` of its circle (a member half hidden behind their partner, whose facing the camera cannot
tell), and may join an open one up to the alone price. A group keeps a known facing among its members.

Two implementations of the same arithmetic, cross-checked by the tests: a crowd runs on numpy arrays,
candidate-major (row k lists the people within reach of candidate k's centre, a KD-tree's answer), so the work grows
with the number of people near each candidate, not with N^2; a small scene runs on Python numbers, where numpy's
overhead per call would outweigh the work.

Every comparison that decides who joins whom treats values within a relative ``TIE`` of each other as equal and
then takes the lowest index: callers that number people canonically (``sid.perception.groups`` sorts them by id
and measures positions from their mean) get the same groups whatever the order, position or heading of the scene,
as rounding moves the values by far less than ``TIE``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # imported where a crowd needs it: scipy.spatial is ~0.3 s of a command's start-up
    from scipy.spatial import cKDTree

from sid.checks import MAX_LENGTH, check_number, check_whole

__all__ = ["MAX_RADIUS_STEPS", "OSpace", "OSpaceModel", "TIE", "find_ospaces"]

# Greedy assignment and refit rounds at most; the partition is stable after 2-4 on the benchmarks.
_MAX_ROUNDS = 8
TIE = 1e-9
"""Relative difference (of the price) under which two costs or savings count as equal, and a cost as on a
threshold: rounding after a rigid motion of the scene moves them by ~1e-15."""
# Up to this many people the search runs on Python numbers (``_find_small``): a handful of people make a few dozen
# candidates, and numpy's overhead per call outweighs the arithmetic. Above it, numpy arrays and a KD-tree finding
# who is within reach of each candidate (the exclusivity test grows with the square of the people listed).
_SMALL_PEOPLE_MAX = 16


MAX_RADIUS_STEPS = 100
"""The most proposals per person (one per centimetre over a metre of radii); the search's arrays grow with them."""


@dataclass(frozen=True)
class OSpaceModel:
    """The o-space model's constants (metres; ``price`` in square metres). See ``GroupParams`` for each meaning."""

    radius_min: float
    radius_max: float
    radius_steps: int
    price: float
    unknown_cost: float
    body_radius: float
    alone_price: float
    angular_weight: float = 1.0
    pair_reach: float = 0.0
    unknown_tolerance: float = 0.2

    def __post_init__(self) -> None:
        far, vast = MAX_LENGTH, MAX_LENGTH**2  # squared and summed downstream: bounded, they stay finite
        check_number("ospace", "radius_min", self.radius_min, low=0, low_open=True, high=far, unit="metres")
        check_number("ospace", "radius_max", self.radius_max, low=self.radius_min, high=far, unit="metres")
        check_number("ospace", "price", self.price, low=0, low_open=True, high=vast, unit="square metres")
        check_number("ospace", "alone_price", self.alone_price, low=0, low_open=True, high=vast, unit="square metres")
        check_number("ospace", "unknown_cost", self.unknown_cost, low=0, high=far, unit="metres")
        check_number("ospace", "body_radius", self.body_radius, low=0, high=far, unit="metres")
        check_number("ospace", "angular_weight", self.angular_weight, low=0, low_open=True)
        check_number("ospace", "pair_reach", self.pair_reach, low=0, high=far, unit="metres")
        check_number("ospace", "unknown_tolerance", self.unknown_tolerance, low=0, high=far, unit="metres")
        check_whole("ospace", "radius_steps", self.radius_steps, low=1, high=MAX_RADIUS_STEPS)

    @cached_property
    def radii(self) -> np.ndarray:
        """The radii (m) of each person's first proposals, ``radius_steps`` evenly from ``radius_min`` to
        ``radius_max``."""
        return np.linspace(self.radius_min, self.radius_max, int(self.radius_steps))

    @cached_property
    def radius_list(self) -> list[float]:
        """``radii`` as Python numbers."""
        return self.radii.tolist()

    @cached_property
    def pair_reach_squared(self) -> float:
        """Squared distance (m^2) up to which two people propose their pair's o-space: ``pair_reach`` squared,
        widened by ``TIE`` so that a pair exactly at ``pair_reach`` stays in after any rigid motion's rounding."""
        return self.pair_reach * self.pair_reach * (1.0 + TIE)

    def pair_proposal(self, a: complex, b: complex, distance2: float) -> tuple[complex, float]:
        """The o-space two people at ``a`` and ``b`` (complex, m), ``distance2`` (m^2) apart, propose together:
        centre their midpoint, radius half their distance clamped to the model's range."""
        return (a + b) * 0.5, min(max(0.5 * math.sqrt(distance2), self.radius_min), self.radius_max)

    @cached_property
    def opening_cost(self) -> float:
        """The highest cost (m^2) at which a person of unknown facing counts towards opening an o-space: standing
        within ``unknown_tolerance`` of its circle, widened by ``TIE`` as every comparison that decides a group."""
        return (self.unknown_cost**2 + self.unknown_tolerance**2) * (1.0 + TIE)

    @cached_property
    def reach(self) -> float:
        """Distance (m) from a centre beyond which nobody can join it: every cost is at least (|p - c| - R)^2, and
        nobody joins at a cost above ``alone_price``."""
        return self.radius_max + math.sqrt(self.alone_price)

    @cached_property
    def reach_squared(self) -> float:
        """The smallest squared distance (m^2) whose rounded square root is ``reach`` or more: d2 < reach_squared
        exactly when sqrt(d2) < reach (the root is monotonic), without taking the root."""
        bound = self.reach * self.reach
        while math.sqrt(bound) >= self.reach:
            bound = math.nextafter(bound, 0.0)
        while math.sqrt(bound) < self.reach:
            bound = math.nextafter(bound, math.inf)
        return bound


@dataclass(frozen=True)
class OSpace:
    """A group found: member indices (ascending, into the input arrays), centre (complex x + iy, m), radius R (m)."""

    members: np.ndarray
    centre: complex
    radius: float


def find_ospaces(
    positions: Sequence[complex],
    facing: Sequence[complex],
    weight: Sequence[float],
    model: OSpaceModel,
    slack: Sequence[float] | None = None,
) -> list[OSpace]:
    """Groups of two or more among people at ``positions`` (complex x + iy, m) with unit ``facing`` (complex, NaN
    when unknown), facing weights in (0, 1] and facing slacks in [0, pi] (rad, 0 when not given); ordered by their
    lowest member index."""
    slack = [0.0] * len(positions) if slack is None else slack
    if len(positions) <= _SMALL_PEOPLE_MAX:
        return _find_small(list(positions), list(facing), list(weight), list(slack), model)
    return _find_crowd(
        np.array(positions, dtype=complex),
        np.array(facing, dtype=complex),
        np.array(weight, dtype=float),
        np.array(slack, dtype=float),
        model,
    )


def _find_crowd(
    positions: np.ndarray, facing: np.ndarray, weight: np.ndarray, slack: np.ndarray, model: OSpaceModel
) -> list[OSpace]:
    """``find_ospaces`` on numpy arrays, candidate-major, with a KD-tree listing the people within reach."""
    from scipy.spatial import cKDTree

    known = ~np.isnan(facing)
    owners = np.flatnonzero(known)
    if len(owners) < 1 or len(positions) < 2:
        return []
    f = np.where(known, facing, 0)
    w = np.where(known, weight, 0.0)
    radii = model.radii
    # The first proposals: each known facing's at every radius, then each close pair's; made by (owner, partner).
    first_owner = owners.repeat(len(radii))
    first_radii = radii[None, :].repeat(len(owners), axis=0).ravel()
    first_centres = positions[first_owner] + first_radii * f[first_owner]
    # Per person (rows): x, y (m), facing x, y, weight, cosine and sine of the facing's slack.
    table = np.array((positions.real, positions.imag, f.real, f.imag, w, np.cos(slack), np.sin(slack)))
    known_list = known.tolist()
    tree = cKDTree(table[:2].T)
    first_partner = first_owner
    if model.pair_reach > 0:
        a, b, pair_centres, pair_radii = _pair_proposals(positions, facing, owners, model)
        first_owner, first_partner = np.concatenate((first_owner, a)), np.concatenate((first_partner, b))
        first_centres = np.concatenate((first_centres, pair_centres))
        first_radii = np.concatenate((first_radii, pair_radii))
    centres, rad = first_centres, first_radii
    labels: list[int] = []
    for _ in range(_MAX_ROUNDS):
        near = _near(tree, centres, model.reach)
        values = table[:, near]
        cost = _costs(values, centres, rad, near >= 0, model)
        previous = labels
        labels, behind = _canonical(_assign(cost, near, known, model).tolist(), known_list)
        label_array = np.array(labels)
        fitted_centres, fitted_radii = _refit(label_array, table, centres[behind], rad[behind], model)
        if labels == previous:
            break
        alone = (label_array[first_owner] < 0) | (label_array[first_partner] < 0)
        centres = np.concatenate((fitted_centres, first_centres[alone]))
        rad = np.concatenate((fitted_radii, first_radii[alone]))
    # Members of group k: a slice of the people sorted by label (stable, so ascending within each group).
    order = np.argsort(label_array, kind="stable")
    bounds = np.searchsorted(label_array[order], np.arange(len(fitted_radii) + 1)).tolist()
    return [
        OSpace(order[start:stop], centre, radius)
        for start, stop, centre, radius in zip(
            bounds[:-1], bounds[1:], fitted_centres.tolist(), fitted_radii.tolist(), strict=True
        )
    ]


def _pair_proposals(
    positions: np.ndarray, facing: np.ndarray, owners: np.ndarray, model: OSpaceModel
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The pair proposals (``OSpaceModel.pair_proposal``) of the ``owners`` (indices of known facings, ascending) at
    ``positions`` (complex, m) within ``pair_reach`` of each other, neither facing (``facing``, complex unit) away
    from the other (``_face_partner``): first and second person (ascending, pairs in
    lexicographic order), centres (complex) and radii (m)."""
    from scipy.spatial import cKDTree

    xy = np.column_stack((positions.real, positions.imag))[owners]
    bound = model.pair_reach_squared
    found = cKDTree(xy).query_pairs(math.sqrt(bound) * (1.0 + 1e-6), output_type="ndarray")  # a superset
    found = found[np.lexsort((found[:, 1], found[:, 0]))]
    a, b = owners[found[:, 0]], owners[found[:, 1]]
    dx, dy = positions[b].real - positions[a].real, positions[b].imag - positions[a].imag
    distance2 = dx * dx + dy * dy
    fa, fb, tie = facing[a], facing[b], TIE * np.sqrt(distance2)
    # As the small path decides it (``_face_partner``).
    keep = (distance2 <= bound) & (fa.real * dx + fa.imag * dy >= -tie) & (fb.real * dx + fb.imag * dy <= tie)
    a, b, distance2 = a[keep], b[keep], distance2[keep]
    radii = np.minimum(np.maximum(0.5 * np.sqrt(distance2), model.radius_min), model.radius_max)
    return a, b, (positions[a] + positions[b]) * 0.5, radii


def _face_partner(fa: complex, fb: complex, dx: float, dy: float, tie: float) -> bool:
    """Whether neither of two people, facing ``fa`` and ``fb`` (complex unit), the second (dx, dy) (m) from the
    first, faces away from the other: each facing within 90 degrees of the direction to the partner (``tie``, m, the
    rounding allowed on the projections). Side by side counts; back to back does not."""
    return fa.real * dx + fa.imag * dy >= -tie and fb.real * dx + fb.imag * dy <= tie


def _near(tree: cKDTree, centres: np.ndarray, reach: float) -> np.ndarray:
    """(M, K) indices of the people within ``reach`` (m) of each centre, ascending, padded with -1; ``tree`` indexes
    the positions."""
    from scipy.spatial import cKDTree

    pairs = cKDTree(np.column_stack((centres.real, centres.imag))).sparse_distance_matrix(
        tree, reach, output_type="ndarray"
    )
    pairs = pairs[pairs["v"] < reach]
    order = np.lexsort((pairs["j"], pairs["i"]))
    row, person = pairs["i"][order], pairs["j"][order]
    counts = np.bincount(row, minlength=len(centres))
    near = np.full((len(centres), max(int(counts.max()), 1)), -1)
    near[row, np.arange(len(row)) - (np.cumsum(counts) - counts)[row]] = person
    return near


def _costs(
    values: np.ndarray, centres: np.ndarray, radii: np.ndarray, listed: np.ndarray, model: OSpaceModel
) -> np.ndarray:
    """(M, K) cost (m^2) of the person in column a of row k joining candidate k; inf where refused (not ``listed``,
    blocked, or not cheaper than standing alone). ``values``: (7, M, K) x, y (m), facing x, y, weight and the
    cosine and sine of the facing's slack of the listed people. Real arithmetic on x and y: numpy's broadcast
    complex products are several times slower."""
    px, py, fx, fy, weight, cos_slack, sin_slack = values
    ox, oy = centres.real[:, None] - px, centres.imag[:, None] - py  # from the person to the centre
    r = radii[:, None]
    rho = np.sqrt(ox**2 + oy**2)
    along, across = ox * fx + oy * fy, np.abs(ox * fy - oy * fx)
    # 2 R rho (1 - cos(phi - s)) = 2 R (rho - along cos s - across sin s) where phi > s (along < rho cos s), else 0.
    turn = np.where(along < rho * cos_slack, rho - along * cos_slack - across * sin_slack, 0.0)
    on_circle = (rho - r) ** 2
    known = on_circle + model.angular_weight * 2.0 * r * np.maximum(turn, 0.0)
    cost = weight * known + (1.0 - weight) * (on_circle + model.unknown_cost**2)
    keep = listed & (cost < model.alone_price * (1.0 - TIE))
    if model.body_radius > 0:
        row, column = np.nonzero(keep)
        blocked = _blocked(px, py, ox, oy, listed, row, column, model.body_radius)
        keep[row[blocked], column[blocked]] = False
    return np.where(keep, cost, np.inf)


def _blocked(
    px: np.ndarray,
    py: np.ndarray,
    ox: np.ndarray,
    oy: np.ndarray,
    listed: np.ndarray,
    row: np.ndarray,
    column: np.ndarray,
    body_radius: float,
) -> np.ndarray:
    """(E,): for each entry e, whether the segment from person a = ``column[e]`` of row k = ``row[e]`` (at ``px``,
    ``py`` [k, a], m) to candidate k's centre, (ox, oy)[k, a] away, passes within ``body_radius`` of another listed
    person b of row k standing between them (projection strictly inside the segment). Anyone between a person and a
    centre is nearer that centre, so within reach, so listed in row k."""
    rx, ry = px[row] - px[row, column][:, None], py[row] - py[row, column][:, None]  # (E, K) from a to each b
    sx, sy = ox[row, column][:, None], oy[row, column][:, None]
    length2 = sx**2 + sy**2
    dot = rx * sx + ry * sy
    cross = rx * sy - ry * sx
    # A person is never between themselves and the centre: dot = 0. Someone on the boundary is not: within TIE of
    # the segment's length along it, or TIE metres where the segment is shorter than a metre (a centre nanometres
    # from the person, where the rounding of a turned scene is no longer small against TIE times its length).
    margin = TIE * np.maximum(length2, np.sqrt(length2))  # TIE x length x max(length, 1 m), m^2
    inside = (dot > margin) & (dot < length2 - margin)
    between = inside & (cross**2 < (1.0 - TIE) * body_radius**2 * length2) & listed[row]
    return np.logical_or.reduce(between, axis=1)


def _assign(cost: np.ndarray, near: np.ndarray, known: np.ndarray, model: OSpaceModel) -> np.ndarray:
    """The candidate each person joins (-1 alone), minimising, greedily, price x (o-spaces opened) + the members'
    costs + alone_price x (people alone).

    Each pass opens every candidate with a positive saving that is the favourite (highest saving, then lowest
    index) of all the people it would serve, so candidates opened together serve nobody twice and the best one is
    always among them; passes repeat until no candidate saves anything. Known facings count towards opening, and
    unknown ones at most ``OSpaceModel.opening_cost``; a candidate that would lower the cost of fewer than two of
    them, or of nobody with a known facing, saves nothing (its o-space would dissolve, and it would keep its one
    person from a pair). Savings and costs within ``TIE`` (of the alone price) of each other count as equal.
    """
    count, tie = len(known), TIE * model.alone_price
    current = np.zeros(count) + model.alone_price
    opened = np.zeros(len(cost), dtype=bool)
    # Unknown facings count only up to opening_cost (where every facing is known, the usual case, nothing to mask).
    known_near = None if known.all() else known[near] & (near >= 0)
    opener = cost if known_near is None else np.where(known_near | (cost <= model.opening_cost), cost, np.inf)
    while True:
        gain = current[near] - opener
        gains = gain > tie
        saving = np.add.reduce(np.where(gains, gain, 0.0), axis=1) - model.price
        # an o-space needs two members, one of them with a known facing
        unopened = np.add.reduce(gains, axis=1) < 2
        if known_near is not None:
            unopened |= ~(gains & known_near).any(axis=1)
        saving[unopened] = -np.inf
        if np.maximum.reduce(saving) <= tie:
            break
        candidate, column = np.nonzero(gain > tie)
        person = near[candidate, column]
        favourite = _first_per_person(person, candidate, -saving[candidate], count, tie)
        accept = saving > tie
        accept[candidate[favourite[person] != candidate]] = False
        opened |= accept
        # Padding (-1) and refused entries are inf in ``opener``: they leave ``current`` as it is.
        np.minimum.at(current, near[accept], opener[accept])
    candidate, column = np.nonzero(opened[:, None] & np.isfinite(cost))
    return _first_per_person(near[candidate, column], candidate, cost[candidate, column], count, tie)


def _first_per_person(person: np.ndarray, candidate: np.ndarray, key: np.ndarray, count: int, tie: float) -> np.ndarray:
    """For each of ``count`` people, the lowest candidate among their (person, candidate) pairs whose ``key`` is
    within ``tie`` of the person's lowest key; -1 for people without a pair."""
    lowest = np.full(count, np.inf)
    np.minimum.at(lowest, person, key)
    keep = key <= lowest[person] + tie
    beyond = int(candidate.max()) + 1 if len(candidate) else 0  # above every candidate: no pair yet
    chosen = np.full(count, beyond)
    np.minimum.at(chosen, person[keep], candidate[keep])
    return np.where(np.isfinite(lowest), chosen, -1)


def _canonical(choices: list[int], known: list[bool]) -> tuple[list[int], list[int]]:
    """Group labels 0, 1, ... per person (-1 alone), numbered in order of each group's lowest member index, from the
    candidate each person chose; candidates chosen by fewer than two people, or by nobody with a known facing,
    dissolve. Also the candidate behind each group. Plain Python: a pass over N small integers, cheaper than numpy's
    calls for a frame."""
    counts: dict[int, int] = {}
    facing: set[int] = set()
    for c, k in zip(choices, known, strict=True):
        if c >= 0:
            counts[c] = counts.get(c, 0) + 1
            if k:
                facing.add(c)
    number: dict[int, int] = {}
    labels = []
    for c in choices:
        if c >= 0 and counts.get(c, 0) >= 2 and c in facing:
            labels.append(number.setdefault(c, len(number)))
        else:
            labels.append(-1)
    return labels, list(number)


def _turned(
    px: np.ndarray,
    py: np.ndarray,
    fx: np.ndarray,
    fy: np.ndarray,
    cos_slack: np.ndarray,
    sin_slack: np.ndarray,
    cx: np.ndarray,
    cy: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Each facing (fx, fy) turned within its cone (slack's cosine and sine) as far towards the centre (cx, cy) as
    the cone allows: the direction to the centre when it lies inside the cone, else the cone's nearer edge; a
    facing with the centre straight behind it (within ``TIE``), or on it (within ``TIE`` metres: the direction to a
    centre on the person is rounding noise), is kept. Positions and centres in m."""
    ox, oy = cx - px, cy - py
    rho = np.sqrt(ox**2 + oy**2)
    along, across = ox * fx + oy * fy, fx * oy - fy * ox  # across > 0: the centre lies counter-clockwise
    off = rho > TIE  # the centre off the person: there is a direction to turn to
    # A full cone (slack pi: no facing known, cos exactly -1) holds every direction, the one straight behind too,
    # which rounding may put a hair outside along >= -rho.
    inside = ((along >= rho * cos_slack) | (cos_slack <= -1.0)) & off
    side = np.where(across > TIE * rho, 1.0, np.where(across < -TIE * rho, -1.0, 0.0)) * off
    edge_x = np.where(side == 0, fx, fx * cos_slack - side * fy * sin_slack)
    edge_y = np.where(side == 0, fy, fy * cos_slack + side * fx * sin_slack)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(inside, ox / rho, edge_x), np.where(inside, oy / rho, edge_y)


def _refit(
    labels: np.ndarray, table: np.ndarray, centres: np.ndarray, radii: np.ndarray, model: OSpaceModel
) -> tuple[np.ndarray, np.ndarray]:
    """Per group (labels 0..G-1), the centre (complex, m) and radius (m) minimising sum w_j |p_j + R f'_j - c|^2
    over its members, R clamped to the model's range, f'_j member j's facing turned within its cone towards the
    group's previous centre (``centres``, (G,) complex); ``table`` (7, N): x, y, facing x, y, weight, cosine and
    sine of the slack per person; ``radii`` (G,) is kept where the facings do not fix R (all parallel).

    With W = sum w, P = sum w p, F = sum w f' (|f'| = 1): c = (P + R F) / W and R = -(sum w <p, f'> - <P, F> / W) /
    (W - |F|^2 / W), <a, b> = Re(a conj(b)).
    """
    px, py, fx, fy, w, cos_slack, sin_slack = table
    member = labels >= 0
    group = np.where(member, labels, 0)
    previous = centres[group] if len(centres) else np.zeros(len(labels), dtype=complex)
    tx, ty = _turned(px, py, fx, fy, cos_slack, sin_slack, previous.real, previous.imag)
    tx, ty = np.where(member & (w > 0), tx, 0.0), np.where(member & (w > 0), ty, 0.0)
    moments = np.array((px, py, tx, ty, px * tx + py * ty, np.ones(len(w)))) * w
    sums = (labels == np.arange(len(radii))[:, None]) @ moments.T  # (G, 6)
    p_sum, f_sum = sums[:, :4].view(complex).T
    pf_sum, total = sums[:, 4], sums[:, 5]
    spread = total - np.abs(f_sum) ** 2 / total
    pull = -(pf_sum - (p_sum * f_sum.conjugate()).real / total)
    fitted = np.divide(pull, spread, out=radii.copy(), where=spread > 1e-9 * total)
    fitted = np.minimum(np.maximum(fitted, model.radius_min), model.radius_max)
    return (p_sum + fitted * f_sum) / total, fitted


# --- Small scenes: the same search on Python numbers, candidate by candidate -----------------------------------------


# Per person: x, y (m), facing x, y (0 when unknown), facing weight (0 when unknown), cosine and sine of the slack.
_Person = tuple[float, float, float, float, float, float, float]
# Relative slack on the distance bound of the exclusivity test's shortcut, far above rounding (a few 1e-16).
_SLACK = 1e-9


# A candidate o-space's row: (person, cost in m^2) of each person who may join it, ascending by person, and the
# saving (m^2) of opening it while everyone is alone (-inf when it lowers the cost of fewer than two of those who
# count towards opening, or of nobody with a known facing: ``_assign``),
# the first pass of every ``_assign_small`` call (a candidate's row does not change between rounds, so neither does
# this).
_Row = tuple[list[tuple[int, float]], float]


def _find_small(
    positions: list[complex], facing: list[complex], weight: list[float], slack: list[float], model: OSpaceModel
) -> list[OSpace]:
    """``find_ospaces`` on Python numbers (positions and facings complex, NaN facing unknown): the crowd path's
    rounds and arithmetic (``_costs``, ``_assign``, ``_refit``) with each candidate's row kept as a list of the
    people who may join it. The first candidates' rows do not change between rounds: computed once."""
    known: list[bool] = []
    people: list[_Person] = []
    first: list[tuple[complex, float]] = []  # (centre, radius) of the first proposals
    first_owner: list[tuple[int, int]] = []  # who made each (twice the same person for a person's own)
    radii = model.radius_list
    for j, (p, f, w, s) in enumerate(zip(positions, facing, weight, slack, strict=True)):
        if f == f:  # a known facing: a complex NaN is unequal to itself
            known.append(True)
            people.append((p.real, p.imag, f.real, f.imag, w, math.cos(s), math.sin(s)))
            first += [(p + r * f, r) for r in radii]
            first_owner += [(j, j)] * len(radii)
        else:
            known.append(False)
            people.append((p.real, p.imag, 0.0, 0.0, 0.0, 1.0, 0.0))
    if sum(known) < 1 or len(known) < 2:
        return []
    if model.pair_reach > 0:
        owners, bound = [j for j, k in enumerate(known) if k], model.pair_reach_squared
        for i, a in enumerate(owners):
            for b in owners[i + 1 :]:
                dx, dy = positions[b].real - positions[a].real, positions[b].imag - positions[a].imag
                distance2 = dx * dx + dy * dy
                if distance2 <= bound and _face_partner(facing[a], facing[b], dx, dy, TIE * math.sqrt(distance2)):
                    first.append(model.pair_proposal(positions[a], positions[b], distance2))
                    first_owner.append((a, b))
    scene = _SmallScene(people, known, model)
    first_rows = scene.rows(first)
    candidates, rows = first, first_rows
    labels: list[int] = []
    for _ in range(_MAX_ROUNDS):
        previous = labels
        labels, behind = _canonical(_assign_small(rows, known, model), known)
        fitted = _refit_small(labels, people, [candidates[k] for k in behind], model)
        if labels == previous:
            break
        alone = [k for k, (a, b) in enumerate(first_owner) if labels[a] < 0 or labels[b] < 0]
        candidates = fitted + [first[k] for k in alone]
        rows = scene.rows(fitted) + [first_rows[k] for k in alone]
    return [
        OSpace(np.array([j for j, label in enumerate(labels) if label == g]), centre, radius)
        for g, (centre, radius) in enumerate(fitted)
    ]


class _SmallScene:
    """The people of a small scene (``_Person`` tuples, and which facings are known) and what the rows of their
    candidate o-spaces need: ``_costs`` and ``_blocked`` row by row, on Python numbers."""

    def __init__(self, people: list[_Person], known: list[bool], model: OSpaceModel) -> None:
        self.people, self.model = people, model
        # Per person, the squared distance (m^2) to the nearest other person (inf when alone).
        nearest = [math.inf] * len(people)
        for a, (ax, ay, *_) in enumerate(people):
            for b in range(a + 1, len(people)):
                bx, by = people[b][0], people[b][1]
                distance2 = (bx - ax) * (bx - ax) + (by - ay) * (by - ay)
                if distance2 < nearest[a]:
                    nearest[a] = distance2
                if distance2 < nearest[b]:
                    nearest[b] = distance2
        # Per person: index, x, y, facing x, y, weight, slack cosine, sine, squared distance to the nearest other,
        # facing known.
        self._table = [(j, *person, nearest[j], known[j]) for j, person in enumerate(people)]
        self._neighbours: dict[int, list[tuple[float, float, float, int]]] = {}

    def rows(self, candidates: list[tuple[complex, float]]) -> list[_Row]:
        """Per candidate o-space (centre complex, radius m), its row (``_Row``): the people who may join it with their
        costs (m^2), the exclusivity test only for those whose nearest neighbour could be in the way.

        A clear facing (weight 1) costs its known-facing term alone (``_costs``). Whether someone is within
        ``reach`` is decided on the squared distance (``OSpaceModel.reach_squared``), as the rounded root would
        decide it."""
        model = self.model
        reach2, sqrt = model.reach_squared, math.sqrt
        limit, tie = model.alone_price * (1.0 - TIE), model.alone_price * TIE
        twice_weight = 2.0 * model.angular_weight
        unknown2, body2, opening = model.unknown_cost**2, model.body_radius**2, model.opening_cost
        slack = 1.0 + _SLACK
        rows = []
        for centre, radius in candidates:
            cx, cy = centre.real, centre.imag
            turn_weight = twice_weight * radius
            entries = []
            saving, gaining, facing = 0.0, 0, False
            for j, px, py, fx, fy, w, cos_slack, sin_slack, nearest, known in self._table:
                ox, oy = cx - px, cy - py  # from the person to the centre
                length2 = ox * ox + oy * oy
                if length2 >= reach2:
                    continue
                rho = sqrt(length2)
                along = ox * fx + oy * fy
                off = rho - radius
                on_circle = off * off
                cost = on_circle
                if along < rho * cos_slack:  # the centre lies outside the facing's cone
                    turn = rho - along * cos_slack - abs(ox * fy - oy * fx) * sin_slack
                    if turn > 0.0:
                        cost += turn_weight * turn
                if w != 1.0:
                    cost = w * cost + (1.0 - w) * (on_circle + unknown2)
                # Only someone nearer than sqrt(length2 + body2) can be in the way: most have no such neighbour.
                if cost < limit and ((length2 + body2) * slack <= nearest or not self._blocked(j, cx, cy)):
                    entries.append((j, cost))
                    if model.alone_price - cost > tie and (known or cost <= opening):
                        saving += model.alone_price - cost
                        gaining += 1
                        facing = facing or known
            rows.append((entries, saving - model.price if gaining >= 2 and facing else -math.inf))
        return rows

    def _blocked(self, j: int, cx: float, cy: float) -> bool:
        """``_blocked`` for person j and the centre (cx, cy) (m): whether someone within the centre's reach stands
        between them, within ``body_radius`` of the segment. Such a person is nearer j than sqrt(length2 + body2),
        length2 the segment's squared length: the search, nearest first, stops at the first one farther."""
        px, py = self.people[j][0], self.people[j][1]
        ox, oy = cx - px, cy - py
        length2 = ox * ox + oy * oy
        body2 = self.model.body_radius**2
        bound = (length2 + body2) * (1.0 + _SLACK)
        margin = TIE * max(length2, math.sqrt(length2))  # as in ``_blocked``
        inner, outer, wide = margin, length2 - margin, (1.0 - TIE) * body2 * length2
        for distance2, rx, ry, b in self._neighbours_of(j):
            if distance2 >= bound:
                return False
            dot = rx * ox + ry * oy
            if inner < dot < outer:
                cross = rx * oy - ry * ox
                if cross * cross < wide and self._within_reach(b, cx, cy):
                    return True
        return False

    def _within_reach(self, b: int, cx: float, cy: float) -> bool:
        """Whether person b is within reach of the centre (cx, cy) (m), as ``rows`` decides it."""
        ox, oy = cx - self.people[b][0], cy - self.people[b][1]
        return ox * ox + oy * oy < self.model.reach_squared

    def _neighbours_of(self, a: int) -> list[tuple[float, float, float, int]]:
        """Everyone else as seen from person a, nearest first: (squared distance m^2, x and y from a to b in m, b).
        Built on first use: most people never need it."""
        if a not in self._neighbours:
            ax, ay = self.people[a][0], self.people[a][1]
            self._neighbours[a] = sorted(
                ((bx - ax) * (bx - ax) + (by - ay) * (by - ay), bx - ax, by - ay, b)
                for b, (bx, by, *_) in enumerate(self.people)
                if b != a
            )
        return self._neighbours[a]


def _assign_small(rows: list[_Row], known: list[bool], model: OSpaceModel) -> list[int]:
    """``_assign`` on rows: the candidate each person joins (-1 alone), by the same greedy passes and the same
    ``TIE``.

    Only candidates with a positive saving are followed from pass to pass: a saving never grows (the people's costs
    only fall, and a sum of smaller or fewer non-negative gains rounds no larger), and a candidate without a positive
    saving is never opened, nor the favourite of anyone whom a candidate with a positive saving serves."""
    count, tie = len(known), TIE * model.alone_price
    current = [model.alone_price] * count
    opened = [False] * len(rows)
    openers = [entries for entries, _ in rows]
    if not all(known):  # unknown facings count towards opening only up to opening_cost
        openers = [[(j, c) for j, c in entries if known[j] or c <= model.opening_cost] for entries in openers]
    savings = [saving for _, saving in rows]
    active = [k for k, saving in enumerate(savings) if saving > tie]
    while active:
        # Each person's favourite: the lowest candidate within ``tie`` of the highest saving among those that lower
        # their cost. A candidate opens when it is the favourite of everyone it serves.
        best, favourite, serves = [-math.inf] * count, [-1] * count, {}
        for k in active:
            saving = savings[k]
            for j, c in openers[k]:
                if c < current[j] - tie and saving > best[j]:
                    best[j] = saving
        for k in active:
            saving, served = savings[k], 0
            for j, c in openers[k]:
                if c < current[j] - tie:
                    served += 1
                    if favourite[j] < 0 and saving >= best[j] - tie:
                        favourite[j] = k
            serves[k] = served
        for k in favourite:
            if k >= 0:
                serves[k] -= 1
        for k in active:
            if serves[k] == 0:
                opened[k] = True
                for j, c in openers[k]:
                    if c < current[j]:
                        current[j] = c
        for k in active:
            # (Gains added in order, not by the builtin ``sum``: it rounds differently from Python 3.12 on.)
            total, gaining, facing = 0.0, 0, False
            for j, c in openers[k]:
                if c < current[j] - tie:
                    total += current[j] - c
                    gaining += 1
                    facing = facing or known[j]
            savings[k] = total - model.price if gaining >= 2 and facing else -math.inf
        active = [k for k in active if savings[k] > tie]
    return _cheapest_opened([entries for entries, _ in rows], opened, count, tie)


def _cheapest_opened(rows: list[list[tuple[int, float]]], opened: list[bool], count: int, tie: float) -> list[int]:
    """For each of ``count`` people, the lowest opened candidate whose cost in its row is within ``tie`` of the
    person's lowest, -1 if none."""
    best = [math.inf] * count
    for k, row in enumerate(rows):
        if opened[k]:
            for j, c in row:
                if c < best[j]:
                    best[j] = c
    chosen = [-1] * count
    for k, row in enumerate(rows):
        if opened[k]:
            for j, c in row:
                if chosen[j] < 0 and c <= best[j] + tie:
                    chosen[j] = k
    return chosen


def _refit_small(
    labels: list[int], people: list[_Person], behind: list[tuple[complex, float]], model: OSpaceModel
) -> list[tuple[complex, float]]:
    """``_refit`` on Python numbers: per group (labels 0..G-1), the centre (complex, m) and radius (m), each
    member's facing turned within its cone towards the centre of the candidate behind the group (``behind``: its
    centre and radius; the radius is kept where the facings do not fix R)."""
    sums = [[0.0] * 6 for _ in behind]  # per group: w x, w y, w fx', w fy', w <p, f'>, w
    for label, (x, y, fx, fy, w, cos_slack, sin_slack) in zip(labels, people, strict=True):
        if label >= 0 and w > 0:
            centre = behind[label][0]
            fx, fy = _turned_small(x, y, fx, fy, cos_slack, sin_slack, centre.real, centre.imag)
            group = sums[label]
            group[0] += x * w
            group[1] += y * w
            group[2] += fx * w
            group[3] += fy * w
            group[4] += (x * fx + y * fy) * w
            group[5] += w
    fitted = []
    for (px, py, fx, fy, pf, total), (_, kept) in zip(sums, behind, strict=True):
        f_norm = math.hypot(fx, fy)
        spread = total - f_norm * f_norm / total
        pull = -(pf - (px * fx + py * fy) / total)
        radius = pull / spread if spread > 1e-9 * total else kept
        radius = min(max(radius, model.radius_min), model.radius_max)
        scale = 1.0 / total  # numpy divides a complex by a real as a product with the reciprocal
        fitted.append((complex((px + radius * fx) * scale, (py + radius * fy) * scale), radius))
    return fitted


def _turned_small(
    px: float, py: float, fx: float, fy: float, cos_slack: float, sin_slack: float, cx: float, cy: float
) -> tuple[float, float]:
    """``_turned`` on Python numbers."""
    ox, oy = cx - px, cy - py
    rho = math.sqrt(ox * ox + oy * oy)
    along, across = ox * fx + oy * fy, fx * oy - fy * ox
    if rho <= TIE:  # the centre on the person: no direction to turn to
        return fx, fy
    if along >= rho * cos_slack or cos_slack <= -1.0:  # inside the cone, or a full cone (as in ``_turned``)
        return ox / rho, oy / rho
    side = 1.0 if across > TIE * rho else -1.0 if across < -TIE * rho else 0.0
    if side == 0:
        return fx, fy
    return fx * cos_slack - side * fy * sin_slack, fy * cos_slack + side * fx * sin_slack
