"""The social layer: people's bodies, their personal space, and the interaction zones of conversational groups.

All geometry is in the world frame (metres, radians). Costs follow Nav2 (uint8):

- body: every cell within ``body_radius`` of a person is LETHAL (254). A person is a physical obstacle, like the
  LiDAR marks this layer replaces (see ``costmap.layers.obstacle``), so the inflation layer inflates bodies as any other
  obstacle. This is the only lethal value the layer writes.
- personal space: an asymmetric Gaussian in the person's frame, ``amplitude * exp(-(u^2 / 2 su^2 + v^2 / 2 sv^2))``
  with u along the facing direction (su = sigma_front ahead, sigma_rear behind) and v sideways (sigma_side);
  a person with unknown orientation (theta None) gets a circle of ``sigma_unknown``.
- group: the interaction zone (``group_zone_polygon``: the convex hull of the detector's o-space polygon and the
  members' positions, grown by ``group_margin``; that covers the space between members, the p-space) costs
  ``group_cost``; outside it the cost falls off as a Gaussian of the distance to the zone (``group_sigma``).

Zones never exceed 252 and the layer never writes 253 or 255. Numbers (defaults) are our choice, documented in
docs/scenario.md (the personal costs they give at Hall's personal distance and how far they reach: docs/parameters.md,
"Personal space at the defaults"); the group zone costs 240, high enough that a cost-aware planner prefers any
reasonable detour, yet below the inscribed value so a robot that starts inside a zone may still leave it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import cast

import cv2
import numpy as np
import shapely
from shapely.geometry import MultiPoint, Polygon
from shapely.geometry.base import BaseGeometry

from costmap.combine import CombinationMethod
from costmap.grid import FREE_SPACE, LETHAL, MAX_NON_OBSTACLE, GridSpec, Window, disjoint
from costmap.layer import Input, LayerInputs, RepaintedLayer
from sid.checks import check_number, check_numbers, check_yaws
from sid.errors import InputError
from sid.perception.group import Group
from sid.perception.people import Person

__all__ = [
    "GROUPS",
    "PEOPLE",
    "SIGMA_RANGE",
    "SocialLayer",
    "SocialParams",
    "group_zone_polygon",
    "paint_bodies",
    "paint_body",
    "paint_group",
    "paint_groups",
    "paint_people",
    "paint_person",
    "repaint",
    "zone_hull",
]


def _people(people: Sequence[Person]) -> tuple[Person, ...]:
    """``people`` as the layers read them: a tuple; each needs a finite pose and an id of its own (else ValueError)."""
    people = tuple(people)
    seen = set()
    for p in people:
        check_numbers(f"person {p.id}", p, ("x", "y"))
        if p.theta is not None:
            check_yaws(f"person {p.id}", p, ("theta",))
        if p.id in seen:
            raise InputError(f"person id {p.id} appears twice")
        seen.add(p.id)
    return people


PEOPLE: Input[tuple[Person, ...]] = Input("people", (), _people)
"""The frame's people (world frame; any sequence, read as a tuple): drawn by the social layer, their LiDAR marks
cleared by the obstacle layer."""

GROUPS: Input[tuple[Group, ...]] = Input("groups", (), tuple)
"""Their groups (members among ``PEOPLE``; any sequence, read as a tuple): zones drawn by the social layer."""

SIGMA_RANGE = (1e-3, 1e3)
"""The spreads (m) a Gaussian of the social layer may have: 1 mm to 1 km, whose exponents stay well inside float32
(the layer's arithmetic) over the cells they reach; margins may be up to the same kilometre."""


@dataclass(frozen=True)
class SocialParams:
    """Social-layer parameters (costs 0..252, distances in metres)."""

    amplitude: float = 200.0
    sigma_front: float = 0.8
    sigma_rear: float = 0.4
    sigma_side: float = 0.5
    sigma_unknown: float = 0.6
    group_cost: float = 240.0
    group_margin: float = 0.3
    group_sigma: float = 0.35
    people_clear_margin: float = 0.1

    def __post_init__(self) -> None:
        check_numbers("social", self, ("amplitude", "group_cost"), low=0, high=MAX_NON_OBSTACLE)
        sigmas = ("sigma_front", "sigma_rear", "sigma_side", "sigma_unknown", "group_sigma")
        check_numbers("social", self, sigmas, low=SIGMA_RANGE[0], high=SIGMA_RANGE[1], unit="metres")
        margins = ("group_margin", "people_clear_margin")
        check_numbers("social", self, margins, low=0, high=SIGMA_RANGE[1], unit="metres")


@lru_cache(maxsize=64)
def _reach(amplitude: float, sigma: float) -> float:
    """Distance (m) at which amplitude * exp(-d^2 / 2 sigma^2) drops below 1 (the smallest non-zero cost)."""
    return sigma * float(np.sqrt(2 * np.log(amplitude))) if amplitude > 1 else 0.0


def _people_by_id(people: Sequence[Person] | Mapping[int, Person]) -> Mapping[int, Person]:
    return people if isinstance(people, Mapping) else {p.id: p for p in people}


def zone_hull(group: Group, people: Sequence[Person] | Mapping[int, Person]) -> BaseGeometry:
    """Convex hull (Polygon, LineString or Point) of the group's o-space vertices and its members' positions (world
    frame, metres). ValueError naming the group for a zone not of shape (K, 2), for no member and no zone vertex (no
    zone to draw), for a member missing from ``people`` and for a value that is not finite."""
    by_id = _people_by_id(people)
    missing = [m for m in group.members if m not in by_id]
    if missing:
        raise InputError(f"group {group.members}: members {missing} are not among the people given")
    zone = np.asarray(group.zone, dtype=float)
    if zone.ndim != 2 or zone.shape[1] != 2:
        raise InputError(f"group {group.members}: zone must be (K, 2) vertices (x, y), got shape {zone.shape}")
    if not group.members and not len(zone):
        raise InputError(f"group {group.members}: no member and no zone vertex, so no zone to draw")
    members = np.array([(by_id[m].x, by_id[m].y) for m in group.members], dtype=float).reshape(-1, 2)
    points = np.vstack([members, zone])
    if not np.isfinite(points).all():
        raise InputError(f"group {group.members}: non-finite member position or zone vertex")
    return cast(MultiPoint, shapely.multipoints(points)).convex_hull  # from the array: no point object per vertex


def group_zone_polygon(
    group: Group, people: Sequence[Person] | Mapping[int, Person], margin: float = SocialParams.group_margin
) -> BaseGeometry:
    """The group's interaction zone as used by the social layer and by the planner's o-space metrics.

    The convex hull of the detector's o-space polygon (``group.zone``) and the members' positions, grown by
    ``margin`` metres: it covers the o-space, the members and the space between them (the p-space). ``people``
    may be a list of persons or a mapping id -> person; every member must be there. A Polygon, except with margin
    0 for members on one spot or one line: their hull, a Point or LineString (a zone of no area).
    """
    check_number("group zone", "margin", margin, low=0, unit="metres")
    hull = zone_hull(group, people)
    return hull.buffer(margin, quad_segs=16) if margin > 0 else hull


_NO_AREA = 1e-12
"""Twice the area (m^2) below which a hull's polygon counts as none (its vertices coincide or are collinear)."""


def _hull_ring(hull: BaseGeometry) -> tuple[list[list[float]], bool]:
    """The vertices [x, y] (world frame, m) of a convex hull (Point, LineString or Polygon), a polygon's ring closed
    and counter-clockwise (as shapely's ``orient(hull, 1.0)``), and whether it bounds an area (a polygon of
    vertices on one spot or one line does not). Python floats, read in one call (``shapely.get_coordinates``): a
    handful of vertices, per group and frame."""
    ring = shapely.get_coordinates(hull).tolist()
    if not isinstance(hull, Polygon):
        return ring, False
    (ox, oy), edges = ring[0], zip(ring[:-1], ring[1:], strict=True)
    twice_area = sum((ax - ox) * (by - oy) - (bx - ox) * (ay - oy) for (ax, ay), (bx, by) in edges)  # shoelace
    if abs(twice_area) < _NO_AREA:  # vertices on one spot or one line, to rounding: painted as a polyline
        return ring, False
    return (ring[::-1] if twice_area < 0 else ring), True


def _bounds(points: list[list[float]]) -> tuple[tuple[float, float], tuple[float, float]]:
    """The bounding box (x min, y min), (x max, y max) of points [x, y]."""
    xs, ys = [x for x, _ in points], [y for _, y in points]
    return (min(xs), min(ys)), (max(xs), max(ys))


def _polynomials(spec: GridSpec, window: Window, x: float, y: float, coefficients: Sequence[float]) -> np.ndarray:
    """Polynomials of degree <= 2 in the offsets (dx, dy) (m, world frame) of the window's cell centres from (x, y),
    float32 (k, rows, cols). ``coefficients``: 9 per polynomial, those of 1, dx, dx^2, dy, dy dx, dy dx^2, dy^2, ...

    Two matrix products (the x powers first, then the y powers): one BLAS call writes every cell of every polynomial,
    faster than a broadcast add of a row and a column vector per polynomial (docs/benchmarks.md, "Costmap"). In
    float32, on offsets from a point near the cells, so the terms stay small: within 1 cost unit of float64 (the
    tests check it).
    """
    xs, ys = spec.cell_axes(window)
    cols = xs.shape[1]
    powers = np.empty((3, cols + len(ys)), dtype=np.float32)  # 1, d, d^2 of the x offsets, then of the y offsets
    powers[0] = 1.0
    powers[1, :cols] = xs[0] - x
    powers[1, cols:] = ys[:, 0] - y
    np.square(powers[1], out=powers[2])
    by_y_power = np.array(coefficients, dtype=np.float32).reshape(-1, 3, 3)
    per_x = np.matmul(by_y_power, powers[:, :cols])  # (k, 3, cols): the sums over the x powers
    return np.matmul(powers[:, cols:].T, per_x)


def _line(x0: float, y0: float, ux: float, uy: float) -> list[float]:
    """``_polynomials`` coefficients of the linear function (dx - x0) ux + (dy - y0) uy."""
    return [-(x0 * ux + y0 * uy), ux, 0.0, uy, 0.0, 0.0, 0.0, 0.0, 0.0]


def _distance_to_hull(spec: GridSpec, window: Window, ring: list[list[float]], polygon: bool) -> np.ndarray:
    """Exact distance (m) from the window's cell centres to a convex hull (0 inside), float32 (rows, cols).

    ring, polygon: ``_hull_ring``'s vertices (a point, a polyline, or a closed counter-clockwise ring; world frame) and
    whether they bound a polygon.

    Written out in numpy rather than ``shapely.distance``, which needs a point object per cell (docs/parameters.md).
    Per edge, in its own frame: t along it from its middle, n across it (positive on the left, the inside of a
    counter-clockwise ring); the distance to the segment is hypot(n, max(|t| - length / 2, 0)), and a point is inside
    the polygon when n >= 0 for every edge. Every edge's t and n come from one ``_polynomials`` call, on offsets from
    the first vertex, and each step then runs on all edges at once; the per-edge setup is in Python floats (a handful
    of edges: numpy's call overhead would dominate).
    """
    ox, oy = ring[0]
    along, across, halves = _edge_fields(ring)
    if not halves:  # a point: one vertex, or vertices that coincide (people on one spot)
        dx, dy = _polynomials(spec, window, ox, oy, _line(0.0, 0.0, 1.0, 0.0) + _line(0.0, 0.0, 0.0, 1.0))
        return cast(np.ndarray, cv2.magnitude(dx, dy))
    fields = _polynomials(spec, window, ox, oy, along + across)
    edges, cols = len(halves), fields.shape[2]
    # Every edge in each call (as one (edges x rows, cols) array for OpenCV): 5 calls whatever the number of edges.
    beyond, normal = fields[:edges], fields[edges:]
    np.abs(beyond, out=beyond)
    beyond -= np.array(halves, dtype=np.float32)[:, None, None]
    flat = beyond.reshape(-1, cols)
    cv2.threshold(flat, 0.0, 0.0, cv2.THRESH_TOZERO, dst=flat)  # max(beyond, 0), in place, faster than numpy
    cv2.magnitude(flat, normal.reshape(-1, cols), magnitude=flat)
    best = beyond.min(axis=0)
    if polygon:  # inside: n >= 0 for every edge
        best *= normal.min(axis=0) < 0
    return best


def _person_box(
    person: Person, params: SocialParams, sigma_front: float
) -> tuple[tuple[float, float], tuple[float, float]]:
    """World bounding box of the cells where the person's personal-space cost is at least 1 (``sigma_front``, m:
    the spread ahead), in Python floats (a person's box is per-frame overhead).

    Those cells form two half-ellipses, ahead and behind, sharing the side semi-axis. An ellipse with semi-axes a
    (along the facing theta) and b reaches hypot(a cos theta, b sin theta) along x: a is the front reach on the side
    the person faces and the rear reach on the other (likewise along y). At 45 degrees, about half the area of the
    rotated rectangle's box."""
    if person.theta is None:
        r = _reach(params.amplitude, params.sigma_unknown)
        return (person.x - r, person.y - r), (person.x + r, person.y + r)
    front, rear, side = (_reach(params.amplitude, s) for s in (sigma_front, params.sigma_rear, params.sigma_side))
    c, s = math.cos(person.theta), math.sin(person.theta)
    ahead_x, behind_x = (front, rear) if c >= 0 else (rear, front)
    ahead_y, behind_y = (front, rear) if s >= 0 else (rear, front)
    return (
        (person.x - math.hypot(behind_x * c, side * s), person.y - math.hypot(behind_y * s, side * c)),
        (person.x + math.hypot(ahead_x * c, side * s), person.y + math.hypot(ahead_y * s, side * c)),
    )


def _gaussian_exponent(sigma_along: float, sigma_side: float, c: float, s: float, log_scale: float) -> list[float]:
    """``_polynomials`` coefficients of log_scale - (u^2 / 2 sigma_along^2 + v^2 / 2 sigma_side^2), with
    u = c dx + s dy along the facing and v = c dy - s dx sideways (m)."""
    a, b = 0.5 / sigma_along**2, 0.5 / sigma_side**2
    dx2, dy_dx, dy2 = -(a * c * c + b * s * s), -2 * (a - b) * c * s, -(a * s * s + b * c * c)
    return [log_scale, 0.0, dx2, 0.0, dy_dx, 0.0, dy2, 0.0, 0.0]


def paint_person(
    costs: np.ndarray, spec: GridSpec, person: Person, params: SocialParams, sigma_front: float | None = None
) -> Window | None:
    """Max the person's personal-space Gaussian into ``costs`` (in place; only the cells it reaches); returns them.

    ``sigma_front`` (m) replaces ``params.sigma_front`` (the tracked-people layer stretches walkers ahead). The
    exponent, log(amplitude) - (u^2 / 2 su^2 + v^2 / 2 sv^2), is a quadratic in the cell offsets: that of the wider
    half's Gaussian, W, and of the narrower half's, N, are evaluated together (``_polynomials``'s products, float32)
    with P = W + lam u' (u' the distance into the wider half), lam large enough that P <= N on the narrower half; then
    min(W, max(N, P)) is W on the wider half and N on the other, in two passes and without a mask. Within 1 cost
    unit of the float64 formula and equal to it at nearly every cell (tests check both; the share of cells that
    differ: docs/parameters.md, "float32 painting").
    ``paint_people`` with one person: the same arithmetic, cell for cell."""
    return paint_people(costs, spec, [person], params, None if sigma_front is None else [sigma_front])[0]


def paint_people(
    costs: np.ndarray,
    spec: GridSpec,
    people: Sequence[Person],
    params: SocialParams,
    sigma_fronts: Sequence[float] | None = None,
) -> list[Window | None]:
    """``paint_person`` for every person (``sigma_fronts``: one per person, or None for ``params.sigma_front``);
    returns their windows, in order.

    People whose windows are about the same size are evaluated together: every person's three exponents on a
    common (rows, cols) block from the corner of their own window, in two batched matrix products, then one pass
    each of max, min, exp and the uint8 cast for all of them, and one ``cv2.max`` per person over its own window
    (the block's cells beyond it are dropped). Per cell the same float32 arithmetic as one person alone; ~10 numpy
    calls per batch instead of per person: on a person's window their fixed cost is a good part of the work
    (docs/parameters.md, "Personal space at the defaults")."""
    if sigma_fronts is not None and len(sigma_fronts) != len(people):
        raise InputError(f"social: {len(sigma_fronts)} sigma_fronts for {len(people)} people")
    windows: list[Window | None] = []
    todo: list[tuple[Person, Window, list[float]]] = []  # (person, window, the 27 coefficients)
    for k, person in enumerate(people):
        front = params.sigma_front if sigma_fronts is None else sigma_fronts[k]
        (x0, y0), (x1, y1) = _person_box(person, params, front)
        window = spec.window((x0, y0), (x1, y1))
        windows.append(window)
        if window is None or params.amplitude == 0:  # a zero amplitude paints nothing (and has no log)
            continue
        todo.append((person, window, _person_coefficients(spec, person, params, front, (x0, y0), (x1, y1))))
    for batch in _batches([w for _, w, _ in todo]):
        chosen = [todo[k] for k in batch]
        _paint_batch(costs, spec, [p for p, _, _ in chosen], [w for _, w, _ in chosen], [c for _, _, c in chosen])
    return windows


def _person_coefficients(
    spec: GridSpec,
    person: Person,
    params: SocialParams,
    front: float,
    low: tuple[float, float],
    high: tuple[float, float],
) -> list[float]:
    """``_polynomials`` coefficients of a person's W, N and P (``paint_person``); ``low``, ``high``: the box."""
    log_amplitude = math.log(params.amplitude)  # exp(log(amplitude) - ...): the scaling rides on the exponent
    if person.theta is None:
        sigma = params.sigma_unknown
        return _gaussian_exponent(sigma, sigma, 1.0, 0.0, log_amplitude) * 3  # min(W, max(W, W)) = W
    (x0, y0), (x1, y1) = low, high
    c, s = math.cos(person.theta), math.sin(person.theta)
    wide, narrow, sign = (
        (front, params.sigma_rear, 1.0) if front >= params.sigma_rear else (params.sigma_rear, front, -1.0)
    )
    wider = _gaussian_exponent(wide, params.sigma_side, c, s, log_amplitude)
    narrower = _gaussian_exponent(narrow, params.sigma_side, c, s, log_amplitude)
    # N - W = -(1 / 2 narrow^2 - 1 / 2 wide^2) u^2 <= -|lam u| wherever |u| <= far: the window's cell centres
    # lie within half a cell of the box, so within far of the person
    far = max(person.x - x0, x1 - person.x) + max(person.y - y0, y1 - person.y) + spec.resolution
    lam = sign * ((0.5 / narrow**2 - 0.5 / wide**2) * far + 1e-3)
    penalised = [*wider]
    penalised[1] += lam * c
    penalised[3] += lam * s
    return wider + narrower + penalised


_BATCH_SLACK = 1.3
"""A batch of people or of hulls is evaluated on a common block of at most this many times their windows' cells."""


def _batches(windows: Sequence[Window]) -> list[list[int]]:
    """The indices of ``windows`` in batches whose common block (the most rows x the most columns) holds at most
    ``_BATCH_SLACK`` times their cells: the largest window first, then each next largest that keeps the batch so.

    Plain ints and comparisons in the inner loop (no ``max`` calls, no tuples): it runs over every person's window
    once per batch, a hundred windows and a dozen batches in a crowd's frame."""
    heights = [w.row1 - w.row0 for w in windows]
    widths = [w.col1 - w.col0 for w in windows]
    areas = [h * w for h, w in zip(heights, widths, strict=True)]
    left = sorted(range(len(windows)), key=areas.__getitem__, reverse=True)  # stable: ties keep their order
    batches = []
    while left:
        first = left[0]
        batch, rest = [first], []
        rows, cols, cells = heights[first], widths[first], areas[first]
        for k in left[1:]:
            r = heights[k] if heights[k] > rows else rows
            c = widths[k] if widths[k] > cols else cols
            if (len(batch) + 1) * r * c <= _BATCH_SLACK * (cells + areas[k]):
                batch.append(k)
                rows, cols, cells = r, c, cells + areas[k]
            else:
                rest.append(k)
        batches.append(batch)
        left = rest
    return batches


def _paint_batch(
    costs: np.ndarray, spec: GridSpec, people: list[Person], windows: list[Window], coefficients: list[list[float]]
) -> None:
    """Max the personal-space Gaussians of ``people`` into ``costs`` over their ``windows`` (``paint_people``)."""
    count = len(people)
    rows = max(w.row1 - w.row0 for w in windows)
    cols = max(w.col1 - w.col0 for w in windows)
    x_powers, y_powers = _powers(spec, windows, [(p.x, p.y) for p in people], rows, cols)
    by_y_power = np.array(coefficients, dtype=np.float32).reshape(count, 3, 3, 3).transpose(1, 0, 2, 3)
    per_x = np.matmul(by_y_power, x_powers)  # (3 exponents, people, 3 y powers, cols)
    wider_e, narrower_e, exponent = np.matmul(y_powers, per_x)  # each (people, rows, cols)
    np.maximum(narrower_e, exponent, out=exponent)
    np.minimum(wider_e, exponent, out=exponent)
    flat = exponent.reshape(-1, cols)
    values = cv2.exp(flat, dst=flat).astype(np.uint8).reshape(count, rows, cols)  # the cast: floor (non-negative)
    for k, w in enumerate(windows):
        view = costs[w.row0 : w.row1, w.col0 : w.col1]
        cv2.max(view, values[k, : w.row1 - w.row0, : w.col1 - w.col0], dst=view)


def paint_group(costs: np.ndarray, spec: GridSpec, hull: BaseGeometry, params: SocialParams) -> Window | None:
    """Max a group's zone cost and its fall-off into ``costs`` (in place); returns the window it reaches.

    ``hull``: the group's ``zone_hull``.

    Distances within 1e-6 m of the zone edge count as inside, so rounding never drops a cell that lies in
    ``group_zone_polygon`` below ``group_cost``. ``paint_groups`` with one hull.
    """
    return paint_groups(costs, spec, [hull], params)[0]


def paint_groups(
    costs: np.ndarray, spec: GridSpec, hulls: Sequence[BaseGeometry], params: SocialParams
) -> list[Window | None]:
    """``paint_group`` for every hull; returns their windows, in order.

    The polygon hulls (a group's usual zone) are evaluated together: every edge's fields of every hull on a common
    block (each hull's edges padded to the most edges by repeating its last one, which leaves the minimum over
    edges as it is) in two batched matrix products, then each step of ``_distance_to_hull`` and of the fall-off once
    for all of them, and one ``cv2.max`` per hull over its own window. Per cell the same float32 arithmetic as one
    hull alone. Points and segments (degenerate zones) are painted one by one."""
    reach = params.group_margin + _reach(params.group_cost, params.group_sigma)
    windows: list[Window | None] = []
    polygons: list[tuple[Window, list[list[float]]]] = []
    for hull in hulls:
        ring, polygon = _hull_ring(hull)
        (x0, y0), (x1, y1) = _bounds(ring)
        window = spec.window((x0 - reach, y0 - reach), (x1 + reach, y1 + reach))
        windows.append(window)
        if window is None:
            continue
        if polygon:
            polygons.append((window, ring))
        else:
            outside = _distance_to_hull(spec, window, ring, polygon)
            _paint_fall_off(costs, [window], outside, params)
    for batch in _batches([w for w, _ in polygons]):
        _paint_polygons(costs, spec, [polygons[k] for k in batch], params)
    return windows


def _edge_fields(ring: list[list[float]]) -> tuple[list[float], list[float], list[float]]:
    """Per edge of a ring, ``_polynomials`` coefficients (offsets from the first vertex) of t along it from its
    middle and of n across it (``_distance_to_hull``), and its half length; repeated vertices skipped."""
    ox, oy = ring[0]
    along: list[float] = []  # the coefficients of every edge's t, then (across) of every edge's n
    across: list[float] = []
    halves = []
    for (ax, ay), (bx, by) in zip(ring[:-1], ring[1:], strict=True):
        length = math.hypot(bx - ax, by - ay)
        if length < 1e-12:  # a repeated vertex (shapely's hulls have none): no direction
            continue
        ux, uy = (bx - ax) / length, (by - ay) / length
        mx, my = (ax + bx) / 2 - ox, (ay + by) / 2 - oy
        along += _line(mx, my, ux, uy)
        across += _line(mx, my, -uy, ux)
        halves.append(length / 2)
    return along, across, halves


def _paint_polygons(
    costs: np.ndarray, spec: GridSpec, polygons: list[tuple[Window, list[list[float]]]], params: SocialParams
) -> None:
    """``paint_groups``' polygon hulls (window, ``_hull_ring``'s closed ring), together."""
    count = len(polygons)
    edges = [_edge_fields(ring) for _, ring in polygons]
    most = max(len(halves) for _, _, halves in edges)
    along, across, halves = [], [], []
    for a, n, h in edges:  # each hull's edges padded to ``most`` with its last one
        along.append(a + a[-9:] * (most - len(h)))
        across.append(n + n[-9:] * (most - len(h)))
        halves.append(h + h[-1:] * (most - len(h)))
    windows = [window for window, _ in polygons]
    rows = max(w.row1 - w.row0 for w in windows)
    cols = max(w.col1 - w.col0 for w in windows)
    x_powers, y_powers = _powers(spec, windows, [ring[0] for _, ring in polygons], rows, cols)
    # (2 most, hulls, 3, 3): every hull's t of each edge, then its n of each edge
    coefficients = np.array([along, across], dtype=np.float32).reshape(2, count, most, 3, 3)
    coefficients = coefficients.transpose(0, 2, 1, 3, 4).reshape(2 * most, count, 3, 3)
    fields = np.matmul(y_powers, np.matmul(coefficients, x_powers))  # (2 most, hulls, rows, cols)
    beyond, normal = fields[:most], fields[most:]
    np.abs(beyond, out=beyond)
    beyond -= np.array(halves, dtype=np.float32).T[:, :, None, None]
    flat = beyond.reshape(-1, cols)
    cv2.threshold(flat, 0.0, 0.0, cv2.THRESH_TOZERO, dst=flat)  # max(beyond, 0), in place, faster than numpy
    cv2.magnitude(flat, normal.reshape(-1, cols), magnitude=flat)
    best = beyond.min(axis=0)
    best *= normal.min(axis=0) < 0  # inside: n >= 0 for every edge
    _paint_fall_off(costs, windows, best, params)


def _powers(
    spec: GridSpec, windows: list[Window], points: Sequence[Sequence[float]], rows: int, cols: int
) -> tuple[np.ndarray, np.ndarray]:
    """Per window, float32 1, d, d^2 of the x offsets (count, 3, cols) and of the y offsets (count, rows, 3) of the
    cell centres of a ``rows`` x ``cols`` block from the window's first cell, from its point [x, y] (world frame, m):
    the centres as ``GridSpec.cell_axes`` computes them, origin + (cell + 0.5) res, and the offsets in float64.
    Both axes in each numpy call ((count, 2, cells) arrays); the two results are views of one array."""
    count, cells = len(windows), max(rows, cols)
    firsts = np.array([(w.col0, w.row0, p[0], p[1]) for w, p in zip(windows, points, strict=True)], dtype=float)
    powers = np.empty((count, 3, 2, cells), dtype=np.float32)  # [1, d, d^2] x [x, y]
    powers[:, 0] = 1.0
    origins = np.array([[spec.origin_x], [spec.origin_y]])
    powers[:, 1] = origins + ((firsts[:, :2, None] + np.arange(cells)) + 0.5) * spec.resolution - firsts[:, 2:, None]
    np.square(powers[:, 1], out=powers[:, 2])
    return powers[:, :, 0, :cols], powers[:, :, 1, :rows].transpose(0, 2, 1)


def _paint_fall_off(costs: np.ndarray, windows: list[Window], outside: np.ndarray, params: SocialParams) -> None:
    """Max the zone cost of the distances ``outside`` (m from the hull, float32 (count, rows, cols) or one
    (rows, cols)) into ``costs`` over each window (its first cells of the block)."""
    cols = outside.shape[-1]
    flat = outside.reshape(-1, cols)
    flat -= np.float32(params.group_margin + 1e-6)
    cv2.threshold(flat, 0.0, 0.0, cv2.THRESH_TOZERO, dst=flat)  # max(outside, 0)
    cv2.multiply(flat, flat, dst=flat, scale=-0.5 / params.group_sigma**2)  # the exponent, in one pass
    unit = cv2.exp(flat, dst=flat)
    # group_cost x exp(0) is exactly group_cost (not so exp(log(group_cost)), which may round below it)
    values = np.multiply(unit, np.float32(params.group_cost), out=unit).astype(np.uint8)  # the cast: floor
    values = values.reshape(-1, *outside.shape[-2:])
    for k, w in enumerate(windows):
        view = costs[w.row0 : w.row1, w.col0 : w.col1]
        cv2.max(view, values[k, : w.row1 - w.row0, : w.col1 - w.col0], dst=view)


def paint_body(costs: np.ndarray, spec: GridSpec, person: Person, body_radius: float) -> Window | None:
    """Mark every cell whose centre lies within ``body_radius`` of the person LETHAL (in place); returns the window."""
    return paint_bodies(costs, spec, [person], body_radius)[0]


def paint_bodies(
    costs: np.ndarray, spec: GridSpec, people: Sequence[Person], body_radius: float
) -> list[Window | None]:
    """``paint_body`` for every person; returns their windows, in order. The squared distances of all of them in a
    few float64 calls on a common block (the same arithmetic, cell for cell, as one body alone), then one masked
    write per body."""
    r = body_radius
    windows = [spec.window((p.x - r, p.y - r), (p.x + r, p.y + r)) for p in people]
    painted = [(w, p) for w, p in zip(windows, people, strict=True) if w is not None]
    if not painted:
        return windows
    rows = max(w.row1 - w.row0 for w, _ in painted)
    cols = max(w.col1 - w.col0 for w, _ in painted)
    cells = max(rows, cols)
    firsts = np.array([(w.col0, w.row0, p.x, p.y) for w, p in painted], dtype=float)
    origins = np.array([[spec.origin_x], [spec.origin_y]])
    # as GridSpec.cell_axes' centres: origin + (cell + 0.5) res; then (x - px)^2 + (y - py)^2 <= r^2 per body
    squares = np.square(
        origins + ((firsts[:, :2, None] + np.arange(cells)) + 0.5) * spec.resolution - firsts[:, 2:, None]
    )
    inside = squares[:, None, 0, :cols] + squares[:, 1, :rows, None] <= r**2
    for k, (w, _) in enumerate(painted):
        costs[w.row0 : w.row1, w.col0 : w.col1][inside[k, : w.row1 - w.row0, : w.col1 - w.col0]] = LETHAL
    return windows


def repaint(
    costs: np.ndarray,
    spec: GridSpec,
    previous: Sequence[Window],
    hulls: Sequence[BaseGeometry],
    people: Sequence[Person],
    params: SocialParams,
    body_radius: float,
    sigma_fronts: Sequence[float] | None = None,
) -> list[Window]:
    """Clear the windows ``previous`` of ``costs``, then paint the group zones ``hulls``, the personal spaces of
    ``people`` (``paint_people``'s ``sigma_fronts``) and their bodies; returns the windows painted, disjoint."""
    for window in previous:
        costs[window.slices] = FREE_SPACE
    painted = paint_groups(costs, spec, hulls, params)
    spaces = paint_people(costs, spec, people, params, sigma_fronts)
    bodies = paint_bodies(costs, spec, people, body_radius)
    # a body inside its own personal space (the usual case) adds no cell: fewer windows for ``disjoint`` to merge
    painted += spaces + [body for body, space in zip(bodies, spaces, strict=True) if not _inside(body, space)]
    return disjoint(painted)


def _inside(window: Window | None, outer: Window | None) -> bool:
    """Whether every cell of ``window`` lies in ``outer`` (None: no cell, inside anything)."""
    if window is None:
        return True
    return (
        outer is not None
        and outer.row0 <= window.row0
        and window.row1 <= outer.row1
        and (outer.col0 <= window.col0 and window.col1 <= outer.col1)
    )


class SocialLayer(RepaintedLayer):
    """Rebuilt from the current people and groups at every update, so it never keeps stale marks.

    Combined by max with its free cells left out (``max_nonzero``): they carry no opinion, as cells outside a Nav2
    layer's bounds, so unknown space stays unknown around people. ``body_radius``: a person's body (m).
    """

    name = "social"
    combination: CombinationMethod = "max_nonzero"
    reads = (PEOPLE, GROUPS)

    def __init__(self, spec: GridSpec, params: SocialParams | None = None, body_radius: float = 0.2) -> None:
        check_number("social layer", "body_radius", body_radius, low=0, low_open=True, unit="metres")
        super().__init__(spec)
        self.params = params or SocialParams()
        self.body_radius = float(body_radius)
        self._painted: list[Window] = []  # windows holding the cells the last update may have painted

    def update_windows(self, inputs: LayerInputs, changed: Sequence[Window]) -> list[Window]:
        """Repaint the layer for the ``PEOPLE`` (world frame) and ``GROUPS`` of ``inputs`` (none: an empty layer);
        returns the windows of the last update's paint (now cleared) and of this one's."""
        people = inputs.get(PEOPLE)
        by_id = _people_by_id(people)
        hulls = [zone_hull(group, by_id) for group in inputs.get(GROUPS)]  # raises on a bad group before any change
        previous = self._painted
        self._painted = repaint(self.costs, self.spec, previous, hulls, people, self.params, self.body_radius)
        return [*previous, *self._painted]
