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

Arrays are candidate-major: row k lists the people within reach of candidate k's centre (all of them in a small
scene, a KD-tree's answer in a crowd), so the work grows with the number of people near each candidate, not with
N^2. Nothing depends on the input order except the breaking of exact ties (lowest index first).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.spatial import cKDTree

from sid.checks import check_number

# Greedy assignment and refit rounds at most; the partition is stable after 2-4 on the benchmarks.
_MAX_ROUNDS = 8
# Up to this many people every person is listed for every candidate (a few numpy calls); above it a KD-tree finds
# who is within reach: its set-up costs more than listing everyone in a small scene, but the exclusivity test grows
# with the square of the people listed per candidate.
_DENSE_PEOPLE_MAX = 12


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


@dataclass(frozen=True)
class OSpace:
    """A group found: member indices (ascending, into the input arrays), centre (complex x + iy, m), radius R (m)."""

    members: np.ndarray
    centre: complex
    radius: float


def find_ospaces(positions: np.ndarray, facing: np.ndarray, weight: np.ndarray, model: OSpaceModel) -> list[OSpace]:
    """Groups of two or more among people at ``positions`` (complex x + iy, m) with unit ``facing`` (complex, NaN
    when unknown) and facing weights in (0, 1]; ordered by their lowest member index."""
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
    # Every cost term is at least (|p - c| - R)^2, so nobody farther than this from a centre can join it.
    reach = model.radius_max + math.sqrt(model.price)
    tree = cKDTree(table[:2].T) if len(positions) > _DENSE_PEOPLE_MAX else None
    if tree is None:  # everyone is listed for every candidate, in input order: one row broadcasts
        values = table[:, None, :]
        offsets = _offsets(values[0], values[1])
    centres, rad = first_centres, first_radii
    labels: list[int] = []
    for _ in range(_MAX_ROUNDS):
        near = _near(positions, tree, centres, reach)
        if tree is not None:
            values = table[:, near]
            offsets = _offsets(values[0], values[1])
        cost = _costs(values, offsets, centres, rad, near >= 0, model)
        previous = labels
        labels, behind = _canonical(_assign(cost, near, known, model.price), known_list)
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


def _near(positions: np.ndarray, tree: cKDTree | None, centres: np.ndarray, reach: float) -> np.ndarray:
    """(M, K) indices of the people within ``reach`` (m) of each centre, ascending, padded with -1; ``tree`` indexes
    the positions (None: every person in input order, -1 where beyond reach)."""
    if tree is None:
        inside = np.abs(positions[None, :] - centres[:, None]) < reach
        return np.where(inside, np.arange(len(positions)), -1)
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


def _offsets(px: np.ndarray, py: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(., K, K) x and y (m) from person a to person b of each row of ``px``, ``py`` (., K)."""
    return px[:, None, :] - px[:, :, None], py[:, None, :] - py[:, :, None]


def _costs(
    values: np.ndarray,
    offsets: tuple[np.ndarray, np.ndarray],
    centres: np.ndarray,
    radii: np.ndarray,
    listed: np.ndarray,
    model: OSpaceModel,
) -> np.ndarray:
    """(M, K) cost (m^2) of the person in column a of row k joining candidate k; inf where refused (not ``listed``,
    blocked, or dearer than standing alone). ``values``: (5, ., K) x, y (m), facing x, y and weight of the listed
    people, ``offsets`` their ``_offsets`` (a row of one broadcasts: everyone listed everywhere). Real arithmetic on x
    and y: numpy's broadcast complex products are several times slower."""
    px, py, fx, fy, weight = values
    ox, oy = centres.real[:, None] - px, centres.imag[:, None] - py  # from the person to the centre
    r = radii[:, None]
    proposal = (r * fx - ox) ** 2 + (r * fy - oy) ** 2
    radial = (np.sqrt(ox**2 + oy**2) - r) ** 2 + model.unknown_cost**2
    cost = weight * proposal + (1.0 - weight) * radial
    keep = listed & (cost < model.price)
    if model.body_radius > 0 and np.logical_or.reduce(keep, axis=None):
        keep &= ~_blocked(offsets, ox, oy, listed, model.body_radius)
    return np.where(keep, cost, np.inf)


def _blocked(
    offsets: tuple[np.ndarray, np.ndarray], ox: np.ndarray, oy: np.ndarray, listed: np.ndarray, body_radius: float
) -> np.ndarray:
    """(M, K): whether the segment from person a of row k to candidate k's centre, (ox, oy)[k, a] away, passes
    within ``body_radius`` of another listed person b of row k standing between them (projection strictly inside
    the segment); ``offsets`` (., K, K) from a to b. Anyone between a person and a centre is nearer that centre, so
    within reach, so listed in row k."""
    rx, ry = offsets
    sx, sy = ox[:, :, None], oy[:, :, None]
    length2 = sx**2 + sy**2
    dot = rx * sx + ry * sy
    cross = rx * sy - ry * sx
    # A person is never between themselves and the centre: dot = 0 on the diagonal.
    between = (dot > 0) & (dot < length2) & (cross**2 < body_radius**2 * length2) & listed[:, None, :]
    return np.logical_or.reduce(between, axis=2)


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


def _canonical(chosen: np.ndarray, known: list[bool]) -> tuple[list[int], list[int]]:
    """Group labels 0, 1, ... per person (-1 alone), numbered in order of each group's lowest member index, from the
    candidate each person chose; candidates chosen by fewer than two known facings dissolve. Also the candidate
    behind each group. Plain Python: a pass over N small integers, cheaper than numpy's calls for a frame."""
    choices = chosen.tolist()
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
