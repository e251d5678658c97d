"""O-space assignment: which people share a conversational o-space, and where its centre lies (world frame, metres).

The model (after the F-formation literature: Setti et al.'s graph-cut detector, PLoS One 2015; written here from
its description, no code taken). An o-space is a circle (centre c, radius R) that its members stand on and face.
Person j with position p_j and unit facing f_j *proposes* the centre p_j + R f_j; joining o-space (c, R) costs

    known facing:    e_j = |p_j + R f_j - c|^2                       (m^2)
    unknown facing:  u_j = (|p_j - c| - R)^2 + unknown_cost^2        (m^2: stands on the circle, facing unexplained)
    doubtful facing: w_j e_j + (1 - w_j) u_j, w_j the facing weight in [0, 1]

and each o-space is charged a price (m^2) for being described, as is every person left alone, so that two people
form a group only when their two costs sum to less than one price (a minimum-description-length choice). A member
whose straight line to the centre passes within ``body_radius`` of another person is refused: the o-space is
exclusive, nobody stands between a member and the centre.

Unlike a fixed stride, each o-space takes its own radius from the data: given its members, the c and R that
minimise the weighted sum of e_j are closed-form (c = mean proposal, R a one-dimensional least squares, clamped to
[radius_min, radius_max]). The search alternates two steps until the partition is stable:

1. assignment: candidate o-spaces are opened greedily by largest saving (the standard greedy heuristic for this
   uncapacitated facility-location problem), each person then takes the cheapest open o-space or stays alone;
2. refit: each group's c and R from its members.

The first candidates are every known-facing person's proposals at several radii (``radius_min`` to ``radius_max``);
later rounds use the refitted groups plus the first proposals of whoever is still alone. Only people with a known
facing open an o-space and a group needs two of them; people with unknown facing may then join one.

Two implementations of the same arithmetic, cross-checked by the tests: a crowd runs on numpy arrays,
candidate-major (row k lists the people within reach of candidate k's centre, a KD-tree's answer), so the work grows
with the number of people near each candidate, not with N^2; a small scene runs on Python numbers, where numpy's
overhead per call would outweigh the work. Nothing depends on the input order except the breaking of exact ties
(lowest index first).
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

from sid.checks import check_number

# Greedy assignment and refit rounds at most; the partition is stable after 2-4 on the benchmarks.
_MAX_ROUNDS = 8
# Up to this many people the search runs on Python numbers (``_find_small``): a handful of people make a few dozen
# candidates, and numpy's overhead per call outweighs the arithmetic. Above it, numpy arrays and a KD-tree finding
# who is within reach of each candidate (the exclusivity test grows with the square of the people listed).
_SMALL_PEOPLE_MAX = 16


@dataclass(frozen=True)
class OSpaceModel:
    """The o-space model's constants (metres; ``price`` in square metres). See ``GroupParams`` for each meaning."""

    radius_min: float
    radius_max: float
    radius_steps: int
    price: float
    unknown_cost: float
    body_radius: float

    def __post_init__(self) -> None:
        check_number("ospace", "radius_min", self.radius_min, low=0, low_open=True, unit="metres")
        check_number("ospace", "radius_max", self.radius_max, low=self.radius_min, unit="metres")
        check_number("ospace", "price", self.price, low=0, low_open=True, unit="square metres")
        check_number("ospace", "unknown_cost", self.unknown_cost, low=0, unit="metres")
        check_number("ospace", "body_radius", self.body_radius, low=0, unit="metres")
        if isinstance(self.radius_steps, bool) or int(self.radius_steps) != self.radius_steps or self.radius_steps < 1:
            raise ValueError(f"ospace: radius_steps must be an integer >= 1, got {self.radius_steps}")

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
    def reach(self) -> float:
        """Distance (m) from a centre beyond which nobody can join it: every cost term is at least (|p - c| - R)^2."""
        return self.radius_max + math.sqrt(self.price)

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
    positions: Sequence[complex], facing: Sequence[complex], weight: Sequence[float], model: OSpaceModel
) -> list[OSpace]:
    """Groups of two or more among people at ``positions`` (complex x + iy, m) with unit ``facing`` (complex, NaN
    when unknown) and facing weights in (0, 1]; ordered by their lowest member index."""
    if len(positions) <= _SMALL_PEOPLE_MAX:
        return _find_small(list(positions), list(facing), list(weight), model)
    return _find_crowd(
        np.array(positions, dtype=complex), np.array(facing, dtype=complex), np.array(weight, dtype=float), model
    )


def _find_crowd(positions: np.ndarray, facing: np.ndarray, weight: np.ndarray, model: OSpaceModel) -> list[OSpace]:
    """``find_ospaces`` on numpy arrays, candidate-major, with a KD-tree listing the people within reach."""
    from scipy.spatial import cKDTree

    known = ~np.isnan(facing)
    owners = np.flatnonzero(known)
    if len(owners) < 2:
        return []
    f = np.where(known, facing, 0)
    w = np.where(known, weight, 0.0)
    radii = model.radii
    first_owner = owners.repeat(len(radii))
    first_radii = radii[None, :].repeat(len(owners), axis=0).ravel()
    first_centres = positions[first_owner] + first_radii * f[first_owner]
    # Per person (rows): x, y (m), facing x, y, weight; and the weighted sums the refit needs, [w p, w f, w <p, f>, w].
    table = np.array((positions.real, positions.imag, f.real, f.imag, w))
    moments = np.array((*table[:4], table[0] * table[2] + table[1] * table[3], np.ones(len(w)))) * w
    known_list = known.tolist()
    tree = cKDTree(table[:2].T)
    centres, rad = first_centres, first_radii
    labels: list[int] = []
    for _ in range(_MAX_ROUNDS):
        near = _near(tree, centres, model.reach)
        values = table[:, near]
        cost = _costs(values, centres, rad, near >= 0, model)
        previous = labels
        labels, behind = _canonical(_assign(cost, near, known, model.price).tolist(), known_list)
        label_array = np.array(labels)
        fitted_centres, fitted_radii = _refit(label_array, moments, rad[behind], model)
        if labels == previous:
            break
        alone = label_array[first_owner] < 0
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
    blocked, or dearer than standing alone). ``values``: (5, M, K) x, y (m), facing x, y and weight of the listed
    people. Real arithmetic on x and y: numpy's broadcast complex products are several times slower."""
    px, py, fx, fy, weight = values
    ox, oy = centres.real[:, None] - px, centres.imag[:, None] - py  # from the person to the centre
    r = radii[:, None]
    proposal = (r * fx - ox) ** 2 + (r * fy - oy) ** 2
    radial = (np.sqrt(ox**2 + oy**2) - r) ** 2 + model.unknown_cost**2
    cost = weight * proposal + (1.0 - weight) * radial
    keep = listed & (cost < model.price)
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
    # A person is never between themselves and the centre: dot = 0.
    between = (dot > 0) & (dot < length2) & (cross**2 < body_radius**2 * length2) & listed[row]
    return np.logical_or.reduce(between, axis=1)


def _assign(cost: np.ndarray, near: np.ndarray, known: np.ndarray, price: float) -> np.ndarray:
    """The candidate each person joins (-1 alone), minimising, greedily, price x (o-spaces opened) + the members'
    costs + price x (people alone).

    Each pass opens every candidate with a positive saving that is the favourite (highest saving, then lowest
    index) of all the people it would serve, so candidates opened together serve nobody twice and the best one is
    always among them; passes repeat until no candidate saves anything. Only known facings count towards opening.
    """
    count = len(known)
    current = np.zeros(count) + price
    opened = np.zeros(len(cost), dtype=bool)
    opener = np.where(known[near], cost, np.inf)
    while True:
        gain = current[near] - opener
        saving = np.add.reduce(np.maximum(gain, 0.0), axis=1) - price
        if np.maximum.reduce(saving) <= 0:
            break
        candidate, column = np.nonzero(gain > 0)
        person = near[candidate, column]
        favourite = _first_per_person(person, candidate, -saving[candidate], count)
        accept = saving > 0
        accept[candidate[favourite[person] != candidate]] = False
        opened |= accept
        # Padding (-1) and refused entries are inf in ``opener``: they leave ``current`` as it is.
        np.minimum.at(current, near[accept], opener[accept])
    candidate, column = np.nonzero(opened[:, None] & np.isfinite(cost))
    return _first_per_person(near[candidate, column], candidate, cost[candidate, column], count)


def _first_per_person(person: np.ndarray, candidate: np.ndarray, key: np.ndarray, count: int) -> np.ndarray:
    """For each of ``count`` people, the candidate of lowest ``key`` among their (person, candidate) pairs, given in
    ascending candidate order (ties: the lowest, as the sort is stable); -1 for people without a pair."""
    order = np.lexsort((key, person))
    person, candidate = person[order], candidate[order]
    first = np.empty(len(person), dtype=bool)
    first[:1] = True
    first[1:] = person[1:] != person[:-1]
    result = np.zeros(count, dtype=int) - 1
    result[person[first]] = candidate[first]
    return result


def _canonical(choices: list[int], known: list[bool]) -> tuple[list[int], list[int]]:
    """Group labels 0, 1, ... per person (-1 alone), numbered in order of each group's lowest member index, from the
    candidate each person chose; candidates chosen by fewer than two known facings dissolve. Also the candidate
    behind each group. Plain Python: a pass over N small integers, cheaper than numpy's calls for a frame."""
    counts: dict[int, int] = {}
    for c, k in zip(choices, known, strict=True):
        if k and c >= 0:
            counts[c] = counts.get(c, 0) + 1
    number: dict[int, int] = {}
    labels = []
    for c in choices:
        if c >= 0 and counts.get(c, 0) >= 2:
            labels.append(number.setdefault(c, len(number)))
        else:
            labels.append(-1)
    return labels, list(number)


def _refit(
    labels: np.ndarray, moments: np.ndarray, radii: np.ndarray, model: OSpaceModel
) -> tuple[np.ndarray, np.ndarray]:
    """Per group (labels 0..G-1), the centre (complex, m) and radius (m) minimising sum w_j |p_j + R f_j - c|^2 over
    its members, R clamped to the model's range; ``moments`` (6, N): w x, w y, w fx, w fy, w <p, f>, w per person;
    ``radii`` (G,) is kept where the facings do not fix R (all parallel).

    With W = sum w, P = sum w p, F = sum w f (|f| = 1): c = (P + R F) / W and R = -(sum w <p, f> - <P, F> / W) /
    (W - |F|^2 / W), <a, b> = Re(a conj(b)).
    """
    sums = (labels == np.arange(len(radii))[:, None]) @ moments.T  # (G, 6)
    p_sum, f_sum = sums[:, :4].view(complex).T
    pf_sum, total = sums[:, 4], sums[:, 5]
    spread = total - np.abs(f_sum) ** 2 / total
    pull = -(pf_sum - (p_sum * f_sum.conjugate()).real / total)
    fitted = np.divide(pull, spread, out=radii.copy(), where=spread > 1e-9 * total)
    fitted = np.minimum(np.maximum(fitted, model.radius_min), model.radius_max)
    return (p_sum + fitted * f_sum) / total, fitted


# --- Small scenes: the same search on Python numbers, candidate by candidate -----------------------------------------


# Per person: x, y (m), facing x, y (0 when unknown) and facing weight (0 when unknown).
_Person = tuple[float, float, float, float, float]
# Relative slack on the distance bound of the exclusivity test's shortcut, far above rounding (a few 1e-16).
_SLACK = 1e-9


# A candidate o-space's row: (person, cost in m^2) of each person who may join it, ascending by person, and the
# saving (m^2) of opening it while everyone is alone, the first pass of every ``_assign_small`` call (a candidate's
# row does not change between rounds, so neither does this).
_Row = tuple[list[tuple[int, float]], float]


def _find_small(
    positions: list[complex], facing: list[complex], weight: list[float], model: OSpaceModel
) -> list[OSpace]:
    """``find_ospaces`` on Python numbers (positions and facings complex, NaN facing unknown): the crowd path's
    rounds and arithmetic (``_costs``, ``_assign``, ``_refit``) with each candidate's row kept as a list of the
    people who may join it. The first candidates' rows do not change between rounds: computed once."""
    known: list[bool] = []
    people: list[_Person] = []
    first: list[tuple[complex, float]] = []  # (centre, radius) of each known facing's first proposals
    first_owner: list[int] = []
    radii = model.radius_list
    for j, (p, f, w) in enumerate(zip(positions, facing, weight, strict=True)):
        if f == f:  # a known facing: a complex NaN is unequal to itself
            known.append(True)
            people.append((p.real, p.imag, f.real, f.imag, w))
            first += [(p + r * f, r) for r in radii]
            first_owner += [j] * len(radii)
        else:
            known.append(False)
            people.append((p.real, p.imag, 0.0, 0.0, 0.0))
    if len(first) < 2 * len(radii):
        return []
    scene = _SmallScene(people, known, model)
    first_rows = scene.rows(first)
    candidates, rows = first, first_rows
    labels: list[int] = []
    for _ in range(_MAX_ROUNDS):
        previous = labels
        labels, behind = _canonical(_assign_small(rows, known, model.price), known)
        fitted = _refit_small(labels, people, [candidates[k][1] for k in behind], model)
        if labels == previous:
            break
        alone = [k for k, o in enumerate(first_owner) if labels[o] < 0]
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
        # Per person: index, x, y, facing x, y, weight, squared distance to the nearest other, facing known.
        self._table = [(j, *person, nearest[j], known[j]) for j, person in enumerate(people)]
        self._neighbours: dict[int, list[tuple[float, float, float, int]]] = {}

    def rows(self, candidates: list[tuple[complex, float]]) -> list[_Row]:
        """Per candidate o-space (centre complex, radius m), its row (``_Row``): the people who may join it with their
        costs (m^2), the exclusivity test only for those whose nearest neighbour could be in the way.

        A clear facing (weight 1) costs the proposal's squared distance alone: the general formula adds
        0 x (radial term) = 0 to it, exactly (the term is finite unless ``unknown_cost`` exceeds 1e154 m, where its
        square overflows). Whether someone is within ``reach`` is decided on the squared distance
        (``OSpaceModel.reach_squared``), as the rounded root would decide it."""
        model = self.model
        reach2, price, sqrt = model.reach_squared, model.price, math.sqrt
        unknown2, body2 = model.unknown_cost**2, model.body_radius**2
        slack = 1.0 + _SLACK
        rows = []
        for centre, radius in candidates:
            cx, cy = centre.real, centre.imag
            entries = []
            saving = 0.0
            for j, px, py, fx, fy, w, nearest, known in self._table:
                ox, oy = cx - px, cy - py  # from the person to the centre
                length2 = ox * ox + oy * oy
                if length2 >= reach2:
                    continue
                dx, dy = radius * fx - ox, radius * fy - oy
                if w == 1.0:
                    cost = dx * dx + dy * dy
                else:
                    radial = sqrt(length2) - radius
                    cost = w * (dx * dx + dy * dy) + (1.0 - w) * (radial * radial + unknown2)
                # Only someone nearer than sqrt(length2 + body2) can be in the way: most have no such neighbour.
                if cost < price and ((length2 + body2) * slack <= nearest or not self._blocked(j, cx, cy)):
                    entries.append((j, cost))
                    if known:
                        saving += price - cost
            rows.append((entries, saving - price))
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
        for distance2, rx, ry, b in self._neighbours_of(j):
            if distance2 >= bound:
                return False
            dot = rx * ox + ry * oy
            if 0 < dot < length2 and self._within_reach(b, cx, cy):
                cross = rx * oy - ry * ox
                if cross * cross < body2 * length2:
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


def _assign_small(rows: list[_Row], known: list[bool], price: float) -> list[int]:
    """``_assign`` on rows: the candidate each person joins (-1 alone), by the same greedy passes.

    Only candidates with a positive saving are followed from pass to pass: a saving never grows (the people's costs
    only fall, and a sum of smaller or fewer non-negative gains rounds no larger), and a candidate without a positive
    saving is never opened, nor the favourite of anyone whom a candidate with a positive saving serves."""
    count = len(known)
    current = [price] * count
    opened = [False] * len(rows)
    openers = [entries for entries, _ in rows]
    if not all(known):
        openers = [[(j, c) for j, c in entries if known[j]] for entries in openers]
    savings = [saving for _, saving in rows]
    active = [k for k, saving in enumerate(savings) if saving > 0]
    while active:
        # Each person's favourite: the candidate of highest saving among those that lower their cost, then lowest.
        # A candidate opens when it is the favourite of everyone it serves.
        best, favourite, serves = [-math.inf] * count, [-1] * count, {}
        for k in active:
            saving, served = savings[k], 0
            for j, c in openers[k]:
                if c < current[j]:
                    served += 1
                    if saving > best[j]:
                        best[j], favourite[j] = saving, k
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
            total = 0.0
            for j, c in openers[k]:
                if c < current[j]:
                    total += current[j] - c
            savings[k] = total - price
        active = [k for k in active if savings[k] > 0]
    return _cheapest_opened([entries for entries, _ in rows], opened, count)


def _cheapest_opened(rows: list[list[tuple[int, float]]], opened: list[bool], count: int) -> list[int]:
    """For each of ``count`` people, the opened candidate of lowest cost in its row (ties: the lowest), -1 if none."""
    chosen = [-1] * count
    best = [math.inf] * count
    for k, row in enumerate(rows):
        if opened[k]:
            for j, c in row:
                if c < best[j]:
                    best[j], chosen[j] = c, k
    return chosen


def _refit_small(
    labels: list[int], people: list[_Person], radii: list[float], model: OSpaceModel
) -> list[tuple[complex, float]]:
    """``_refit`` on Python numbers: per group (labels 0..G-1), the centre (complex, m) and radius (m); ``radii``
    (G) is kept where the facings do not fix R."""
    sums = [[0.0] * 6 for _ in radii]  # per group: w x, w y, w fx, w fy, w <p, f>, w
    for label, (x, y, fx, fy, w) in zip(labels, people, strict=True):
        if label >= 0:
            group = sums[label]
            group[0] += x * w
            group[1] += y * w
            group[2] += fx * w
            group[3] += fy * w
            group[4] += (x * fx + y * fy) * w
            group[5] += w
    fitted = []
    for (px, py, fx, fy, pf, total), kept in zip(sums, radii, strict=True):
        f_norm = math.hypot(fx, fy)
        spread = total - f_norm * f_norm / total
        pull = -(pf - (px * fx + py * fy) / total)
        radius = pull / spread if spread > 1e-9 * total else kept
        radius = min(max(radius, model.radius_min), model.radius_max)
        scale = 1.0 / total  # numpy divides a complex by a real as a product with the reciprocal
        fitted.append((complex((px + radius * fx) * scale, (py + radius * fy) * scale), radius))
    return fitted
