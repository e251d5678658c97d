"""Wide rings: groups whose members all stand on one circle facing its centre, wider than the o-space search's radii
(world frame, metres, radians).

The o-space search (``sid.perception.ospace``) proposes centres at most ``radius_max`` (0.8 m) from each person, as
wide as the benchmarks' groups are; a reception's circle of 8-12 people on 1.1-1.6 m comes out of it in arcs.
``joined_rings`` joins up to ``MAX_PARTS`` groups (or groups and people alone) when together they make a ring of at
least ``MIN_MEMBERS`` people: the circle fitted to their positions (least squares, Kasa's algebraic fit) has a radius
of at most ``RingModel.radius_max``, every member stands within ``tolerance`` of it, every known facing points within
``facing_tolerance`` (or the facings' slack, when wider) of its centre, and nobody else stands inside it (the
o-space is exclusive); the parts joined on the way (three people or more) must each make such an arc, nobody inside
asked. Someone alone whose facing is unknown joins a ring of ``MIN_MEMBERS`` or more standing on its circle, and
never makes one. The test is geometric and strict on purpose: the search's merges are priced, and two neighbouring
conversations never pass this one, as each member faces their own group's centre.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from sid.checks import check_number
from sid.perception.ospace import TIE

__all__ = ["MAX_NEAR", "MAX_PARTS", "MIN_MEMBERS", "Ring", "RingModel", "fit_ring", "joined_rings"]

MIN_MEMBERS = 6
"""The fewest people a joined ring holds: n people 1 m apart on a circle stand 1 / (2 sin(pi / n)) from its centre,
within the o-space search's radii (0.85 m) up to five; wider circles hold six or more."""
MAX_PARTS = 4
"""The most parts one join takes: seven people on a 1.6 m circle came out of the search as arcs of 2, 2 and 3, no
two of which hold six people, and stayed apart when joins took two parts at a time."""
MAX_NEAR = 10
"""A group with more parts than this near it joins two at a time only: the joins of three and four parts grow with
the cube of their number (an audience of 60 around a speaker, all facing one spot, took 164 ms a call), and a ring's
arcs have few neighbours."""
_COLLINEAR = 1e-9
"""Points whose spread matrix's determinant is below this share of its squared trace lie on a line: no circle."""
_ANGLE_TIE = TIE
"""rad: a facing this close to the edge of its cone is inside it, so that a rigid motion's rounding (~1e-15)
cannot move a member out (the o-space search's relative ``TIE`` serves the radius bound and the ranking of joins
too)."""


@dataclass(frozen=True)
class RingModel:
    """When arcs make one ring: its largest radius (m), how far a member may stand off the circle (m), and how far a
    member's facing may point from the centre (rad; the facings' own slack when wider). ``radius_max`` 0 turns the
    joining off."""

    radius_max: float
    tolerance: float
    facing_tolerance: float

    def __post_init__(self) -> None:
        check_number("rings", "radius_max", self.radius_max, low=0, high=1e3, unit="metres")
        check_number("rings", "tolerance", self.tolerance, low=0, high=1e3, unit="metres")
        check_number("rings", "facing_tolerance", self.facing_tolerance, low=0, high=math.pi / 2)


@dataclass(frozen=True)
class Ring:
    """A circle fitted to people: centre (complex x + iy, m), radius (m) and the largest distance of one of them
    from it (m)."""

    centre: complex
    radius: float
    deviation: float


def fit_ring(points: Sequence[complex]) -> Ring | None:
    """The least-squares circle through ``points`` (complex, m; three or more): Kasa's algebraic fit, minimising
    sum (2 a x + 2 b y + c - x^2 - y^2)^2 over the points measured from their mean; None when they are (nearly)
    collinear. Its normal equations are solved in closed form on Python numbers: for a ring's handful of points
    ``numpy.linalg.lstsq``'s overhead per call is most of the time (the tests hold the two to each other)."""
    count = len(points)
    if count < 3:
        return None
    mean = sum(points, 0j) / count
    xs, ys = [p.real - mean.real for p in points], [p.imag - mean.imag for p in points]
    sxx = syy = sxy = sxz = syz = sz = 0.0
    for x, y in zip(xs, ys, strict=True):
        z = x * x + y * y
        sxx += x * x
        syy += y * y
        sxy += x * y
        sxz += x * z
        syz += y * z
        sz += z
    det = sxx * syy - sxy * sxy
    if det <= _COLLINEAR * (sxx + syy) ** 2:
        return None
    a = (sxz * syy - syz * sxy) / (2.0 * det)
    b = (syz * sxx - sxz * sxy) / (2.0 * det)
    radius = math.sqrt(sz / count + a * a + b * b)
    deviation = max(abs(math.hypot(x - a, y - b) - radius) for x, y in zip(xs, ys, strict=True))
    return Ring(complex(a, b) + mean, radius, deviation)


def joined_rings(
    members: list[list[int]],
    centres: list[complex],
    positions: Sequence[complex],
    facing: Sequence[complex],
    slack: float,
    model: RingModel,
) -> tuple[list[list[int]], list[complex]]:
    """``members`` (indices into ``positions``, m, and ``facing``, complex unit or NaN when unknown; groups in order
    of their lowest index) and their ``centres`` (complex, m) after joining, while up to ``MAX_PARTS`` groups and
    people alone make a ring (module docstring): the join whose ring fits best first (lowest deviation, then lowest
    indices); a joined group's centre is its ring's. ``slack``: the facings' cone half-width (rad)."""
    groups, centres = [list(g) for g in members], list(centres)
    if model.radius_max <= 0 or len(positions) < MIN_MEMBERS:
        return groups, centres
    grouped = {j for g in groups for j in g}
    alone = [j for j in range(len(positions)) if j not in grouped]
    join = _Joins(positions, facing, slack, model)
    while True:
        # A part: another group (h >= 0) or someone alone (h = -1 - their index).
        parts = [*range(len(groups)), *(-1 - j for j in alone)]
        people = {h: groups[h] if h >= 0 else [-1 - h] for h in parts}
        means = {h: sum((positions[j] for j in people[h]), 0j) / len(people[h]) for h in parts}
        best: tuple[Ring, list[int]] | None = None
        for g in range(len(groups)):
            near = [
                h
                for h in parts
                if (h > g or h < 0) and abs(means[g] - means[h]) <= join.diameter and join.close(groups[g], people[h])
            ]
            for ring, chosen in join.rings(groups[g], [(h, people[h]) for h in near]):
                if best is None or ring.deviation < best[0].deviation * (1.0 - TIE):
                    best = (ring, [g, *chosen])
        if best is None:
            return groups, centres
        ring, (g, *chosen) = best
        groups[g] = sorted(groups[g] + [j for h in chosen for j in people[h]])
        centres[g] = ring.centre
        for h in sorted((h for h in chosen if h >= 0), reverse=True):
            del groups[h], centres[h]
        alone = [j for j in alone if -1 - j not in chosen]


class _Joins:
    """The rings a group makes with parts near it (``joined_rings``): ``positions`` (complex, m), ``facing``
    (complex unit, NaN unknown), the facings' ``slack`` (rad) and the ``model``."""

    def __init__(self, positions: Sequence[complex], facing: Sequence[complex], slack: float, model: RingModel) -> None:
        self.positions, self.facing, self.slack, self.model = positions, facing, slack, model
        self.diameter = 2.0 * (model.radius_max + model.tolerance)

    def close(self, these: list[int], those: list[int]) -> bool:
        """Whether everyone of ``these`` stands within the widest ring's diameter of everyone of ``those``."""
        positions, diameter = self.positions, self.diameter
        return all(abs(positions[a] - positions[b]) <= diameter for a in these for b in those)

    def rings(self, group: list[int], near: list[tuple[int, list[int]]]) -> list[tuple[Ring, list[int]]]:
        """Each ring of ``group`` with up to ``MAX_PARTS`` - 1 of the ``near`` parts ((key, people), in order) and
        the keys it took: taken in order, each added part close to the ones before it, each union short of
        ``MIN_MEMBERS`` an arc when it holds three people or more; with more than ``MAX_NEAR`` parts near, one part at
        a time. Someone alone of unknown facing joins a group of ``MIN_MEMBERS`` or more on its own."""
        found: list[tuple[Ring, list[int]]] = []
        facing = self.facing
        parts = MAX_PARTS if len(near) <= MAX_NEAR else 2

        def grow(union: list[int], keys: list[int], start: int) -> None:
            for k in range(start, len(near)):
                key, people = near[k]
                unknown = key < 0 and facing[people[0]] != facing[people[0]]
                if unknown and (keys or len(union) < MIN_MEMBERS):
                    continue
                if keys and not self.close(union, people):
                    continue
                joined = sorted(union + people)
                if len(joined) >= MIN_MEMBERS:
                    ring = _ring(joined, self.positions, facing, self.slack, self.model)
                    if ring is not None:
                        found.append((ring, [*keys, key]))
                elif len(keys) + 2 < parts and (
                    len(joined) < 3 or _arc(joined, self.positions, facing, self.slack, self.model)
                ):
                    grow(joined, [*keys, key], k + 1)

        grow(group, [], 0)
        return found


def _ring(
    union: list[int], positions: Sequence[complex], facing: Sequence[complex], slack: float, model: RingModel
) -> Ring | None:
    """The ring ``union`` makes, or None where it is no ring (an arc that is not one, ``_arc``, or someone else
    inside)."""
    ring = _arc(union, positions, facing, slack, model)
    if ring is None:
        return None
    inside = ring.radius - model.tolerance
    chosen = set(union)
    if any(abs(p - ring.centre) < inside for k, p in enumerate(positions) if k not in chosen):
        return None
    return ring


def _arc(
    union: list[int], positions: Sequence[complex], facing: Sequence[complex], slack: float, model: RingModel
) -> Ring | None:
    """The circle ``union`` stands on, or None where it is none (too wide, a member off the circle or looking away
    from the centre)."""
    ring = fit_ring([positions[j] for j in union])
    if ring is None or ring.radius > model.radius_max * (1.0 + TIE) or ring.deviation > model.tolerance:
        return None
    limit = max(slack, model.facing_tolerance) + _ANGLE_TIE
    for j in union:
        f = facing[j]
        if f == f:  # a known facing: within ``limit`` of the direction to the centre
            towards = ring.centre - positions[j]
            along, across = f.real * towards.real + f.imag * towards.imag, f.real * towards.imag - f.imag * towards.real
            if abs(math.atan2(across, along)) > limit:
                return None
    return ring
