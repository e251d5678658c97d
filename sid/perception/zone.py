"""Where the rays of a group's members meet, and the interaction zone they make: the convex hull of the crossings
(area, centroid = interest point; shoelace formula) and the members' spread about it. World frame (metres), points
as complex numbers x + iy. Used by every group method (``sid.perception.groups``, ``sid.perception.rays``)."""

from __future__ import annotations

import itertools
import math
import operator
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from sid.perception.groups import GroupParams

__all__ = ["PARALLEL", "SHALLOW", "convex_hull", "member_crossings", "shoelace", "spread", "zone_of"]

# |sin| of the angle between two rays below which they count as parallel (their crossing is rounding noise).
PARALLEL = 1e-9
# |sin| of the angle between the rays of a face-to-face pair below which they meet at their midpoint, crossing or not
# (``sid.perception.rays``): 20 degrees from anti-parallel. There a crossing moves ~2 cm per degree of facing noise
# for people 0.8 m apart (~1 cm at 34 degrees), and the switch to the midpoint moves the point by at most 7 cm.
SHALLOW = math.sin(math.radians(20.0))
# Hull area (m^2) below which the polygon of crossings is treated as degenerate (a point or a segment).
_DEGENERATE_AREA = 1e-9
# Sort key of a point x + iy: (x, y).
_BY_X_THEN_Y = operator.attrgetter("real", "imag")


def member_crossings(
    positions: list[complex], facing: list[complex], groups: list[list[int]], params: GroupParams
) -> list[list[complex]]:
    """Per group (member indices into ``positions``), where its members' rays meet, pair by pair in the order of
    ``itertools.combinations``: ``sid.perception.rays.ray_meetings`` on Python numbers, for the o-space method's few
    members (numpy's overhead per call outweighs the work). The same operations in the same order, so the same bits;
    a test checks it."""
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
            if abs(denom) > PARALLEL and not (face_to_face and abs(denom) < SHALLOW):
                s, t = (dx * fjy - dy * fjx) / denom, (dx * fiy - dy * fix) / denom
                if max(abs(s - half), abs(t - half)) <= half:
                    found.append(pi + s * fi)
                    continue
            if face_to_face:
                found.append(0.5 * (pi + positions[j]))
        crossings.append(found)
    return crossings


def zone_of(crossings: list[complex]) -> tuple[float, complex, np.ndarray]:
    """Hull area (m^2), centre (complex x + iy, m) and (K, 2) zone polygon of ``crossings`` (at least one)."""
    hull = convex_hull(crossings) if len(crossings) >= 3 else []
    area, centre = shoelace(hull) if len(hull) >= 3 else (0.0, 0j)
    if area > _DEGENERATE_AREA:
        return area, centre, np.array([(p.real, p.imag) for p in hull])
    centre, zone = _degenerate_zone(crossings)
    return 0.0, centre, zone


def spread(member_positions: list[complex], centre: complex) -> float:
    """D (m): the mean distance of the members to ``centre``, the distances summed exactly (``math.fsum``), so
    that the value depends neither on the members' order nor on the machine."""
    return math.fsum([abs(p - centre) for p in member_positions]) / len(member_positions)


def convex_hull(points: list[complex]) -> list[complex]:
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


def shoelace(polygon: list[complex]) -> tuple[float, complex]:
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
