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
docs/scenario.md: personal costs reach ~65 at Hall's personal distance (1.2 m) ahead and fade within ~1.5 m; the
group zone costs 240, high enough that a cost-aware planner prefers any reasonable detour, yet below the
inscribed value so a robot that starts inside a zone may still leave it.
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
from costmap.grid import FREE_SPACE, LETHAL, MAX_NON_OBSTACLE, GridSpec, Window, union
from costmap.layer import Layer, LayerInputs
from sid.checks import check_number, check_numbers
from sid.perception.groups import Group
from sid.perception.people import Person


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
        check_numbers("social", self, sigmas, low=0, low_open=True, unit="metres")
        check_numbers("social", self, ("group_margin", "people_clear_margin"), low=0, unit="metres")


_SQRT_HALF = math.sqrt(0.5)


@lru_cache(maxsize=64)
def _reach(amplitude: float, sigma: float) -> float:
    """Distance (m) at which amplitude * exp(-d^2 / 2 sigma^2) drops below 1 (the smallest non-zero cost)."""
    return sigma * float(np.sqrt(2 * np.log(amplitude))) if amplitude > 1 else 0.0


def _people_by_id(people: Sequence[Person] | Mapping[int, Person]) -> Mapping[int, Person]:
    return people if isinstance(people, Mapping) else {p.id: p for p in people}


def zone_hull(group: Group, people: Sequence[Person] | Mapping[int, Person]) -> BaseGeometry:
    """Convex hull (Polygon, LineString or Point) of the group's o-space vertices and its members' positions."""
    by_id = _people_by_id(people)
    missing = [m for m in group.members if m not in by_id]
    if missing:
        raise ValueError(f"group {group.members}: members {missing} are not among the people given")
    members = np.array([(by_id[m].x, by_id[m].y) for m in group.members], dtype=float).reshape(-1, 2)
    points = np.vstack([members, np.asarray(group.zone, dtype=float).reshape(-1, 2)])
    if not np.isfinite(points).all():
        raise ValueError(f"group {group.members}: non-finite member position or zone vertex")
    return cast(MultiPoint, shapely.multipoints(points)).convex_hull  # from the array: no point object per vertex


def group_zone_polygon(
    group: Group, people: Sequence[Person] | Mapping[int, Person], margin: float = SocialParams.group_margin
) -> Polygon:
    """The group's interaction zone as used by the social layer and by the planner's o-space metrics.

    The convex hull of the detector's o-space polygon (``group.zone``) and the members' positions, grown by
    ``margin`` metres: it covers the o-space, the members and the space between them (the p-space). ``people``
    may be a list of persons or a mapping id -> person; every member must be there.
    """
    check_number("group zone", "margin", margin, low=0, unit="metres")
    grown = zone_hull(group, people).buffer(margin, quad_segs=16) if margin > 0 else zone_hull(group, people)
    if not isinstance(grown, Polygon) or grown.is_empty or grown.area == 0:
        raise ValueError(f"group {group.members}: the zone is degenerate (collinear points); use a margin > 0")
    return grown


def _hull_ring(hull: BaseGeometry) -> tuple[np.ndarray, bool]:
    """The vertices of a convex hull (Point, LineString or Polygon) as an (K, 2) array, a polygon's ring closed
    and counter-clockwise (as shapely's ``orient(hull, 1.0)``), and whether it is a polygon."""
    if not isinstance(hull, Polygon):
        return np.asarray(hull.coords, dtype=float).reshape(-1, 2), False
    ring = np.asarray(hull.exterior.coords, dtype=float)
    x, y = ring[:, 0], ring[:, 1]
    clockwise = float(np.dot(x[:-1], y[1:]) - np.dot(x[1:], y[:-1])) < 0  # shoelace: twice the signed area
    return (ring[::-1] if clockwise else ring), True


def _distance_to_hull(xs: np.ndarray, ys: np.ndarray, ring: np.ndarray, polygon: bool) -> np.ndarray:
    """Exact distance (m) from points (xs (1, cols) and ys (rows, 1), broadcast together) to a convex hull (0 inside).

    ring, polygon: ``_hull_ring``'s vertices (a point, a polyline, or a closed counter-clockwise ring) and whether
    they bound a polygon.

    Written out in numpy rather than ``shapely.distance``, which needs a point object per cell, and one pass per
    edge (keeping the running minimum) rather than all edges at once: both are faster (docs/parameters.md). Per
    edge, in its own frame: t along it from its start, n across it (positive on the left, the inside of a
    counter-clockwise ring); the squared distance to the segment is n^2 + (t - clip(t, 0, length))^2, and a point
    is inside the polygon when n >= 0 for every edge. The arithmetic runs in preallocated buffers, in the offsets'
    dtype (float32 from ``_local_axes``: Python floats do not promote it), within 1 cost unit of float64.
    """
    if len(ring) == 1:
        return np.hypot(xs - ring[0, 0], ys - ring[0, 1])
    shape = np.broadcast_shapes(np.shape(xs), np.shape(ys))
    dtype = np.result_type(xs, ys)
    best = np.full(shape, np.inf, dtype=dtype)
    least_across = np.full(shape, np.inf, dtype=dtype)
    along, across, beyond = (np.empty(shape, dtype=dtype) for _ in range(3))
    for (ax, ay), (bx, by) in zip(ring[:-1].tolist(), ring[1:].tolist(), strict=True):
        length = math.hypot(bx - ax, by - ay)
        if length < 1e-12:  # a repeated vertex (shapely's hulls have none): nothing to divide by
            continue
        ux, uy = (bx - ax) / length, (by - ay) / length
        dx, dy = xs - ax, ys - ay
        np.add(dx * ux, dy * uy, out=along)
        np.subtract(dy * ux, dx * uy, out=across)
        if polygon:
            np.minimum(least_across, across, out=least_across)
        np.clip(along, 0.0, length, out=beyond)
        np.subtract(along, beyond, out=beyond)
        np.square(across, out=across)
        across += np.square(beyond, out=beyond)
        np.minimum(best, across, out=best)
    distance = np.sqrt(best, out=best)
    if polygon:
        distance[least_across >= 0] = 0.0
    return distance


def _person_box(
    person: Person, params: SocialParams, sigma_front: float
) -> tuple[tuple[float, float], tuple[float, float]]:
    """World bounding box of the cells where the person's personal-space cost is at least 1 (``sigma_front``, m:
    the spread ahead)."""
    if person.theta is None:
        r = _reach(params.amplitude, params.sigma_unknown)
        return (person.x - r, person.y - r), (person.x + r, person.y + r)
    front, rear, side = (_reach(params.amplitude, s) for s in (sigma_front, params.sigma_rear, params.sigma_side))
    c, s = math.cos(person.theta), math.sin(person.theta)
    # The rectangle's corners (u along the facing, v sideways), in Python floats: a person's box is per-frame overhead.
    corners = [(u, v) for u in (front, -rear) for v in (side, -side)]
    xs = [person.x + c * u - s * v for u, v in corners]
    ys = [person.y + s * u + c * v for u, v in corners]
    return (min(xs), min(ys)), (max(xs), max(ys))


def _local_axes(spec: GridSpec, window: Window, x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
    """Cell-centre offsets from (x, y) in a window as float32 (1, cols) and (rows, 1): float32 for the speed of the
    per-cell arithmetic (docs/parameters.md), exact to ~1e-6 m over a few metres."""
    xs, ys = spec.cell_axes(window)
    return (xs - x).astype(np.float32), (ys - y).astype(np.float32)


def paint_person(
    costs: np.ndarray, spec: GridSpec, person: Person, params: SocialParams, sigma_front: float | None = None
) -> Window | None:
    """Max the person's personal-space Gaussian into ``costs`` (in place; only the cells it reaches); returns them.

    ``sigma_front`` (m) replaces ``params.sigma_front`` (the tracked-people layer stretches walkers ahead). In float32
    (``_local_axes``), with the offsets scaled by sqrt(1/2) / sigma first (u along the facing, by the front sigma,
    then the cells behind by front / rear), so that the exponent is -(u^2 + v^2): within 1 cost unit of the float64
    formula, which it matches at all but a few cells in a million (a test checks both)."""
    front = params.sigma_front if sigma_front is None else sigma_front
    window = spec.window(*_person_box(person, params, front))
    if window is None:
        return None
    dx, dy = _local_axes(spec, window, person.x, person.y)
    if person.theta is None:
        k = _SQRT_HALF / params.sigma_unknown
        u, v = dx * k, dy * k  # (1, cols) and (rows, 1)
        exponent = np.add(np.square(u, out=u), np.square(v, out=v))
    else:
        c, s = math.cos(person.theta), math.sin(person.theta)
        kf, ks = _SQRT_HALF / front, _SQRT_HALF / params.sigma_side
        u = (c * kf) * dx + (s * kf) * dy
        np.multiply(u, front / params.sigma_rear, out=u, where=u < 0)  # behind the person: the rear sigma
        v = (c * ks) * dy - (s * ks) * dx
        exponent = np.square(u, out=u)
        exponent += np.square(v, out=v)
    np.negative(exponent, out=exponent)
    _max_into(costs[window.slices], _exp(exponent), params.amplitude)
    return window


def _exp(values: np.ndarray) -> np.ndarray:
    """exp of a float32 array, in place: OpenCV's vectorised exp, ~4x numpy's here for float32, within a few ulp of
    it (docs/benchmarks.md)."""
    return cv2.exp(values, dst=values)


def _max_into(view: np.ndarray, unit: np.ndarray, scale: float) -> None:
    """view = max(view, floor(scale x unit)) in place, for a uint8 ``view`` and float ``unit`` with scale x unit in
    [0, 253): the product is truncated to uint8 as it is written (no float temporary)."""
    scaled = np.multiply(unit, scale, out=np.empty(unit.shape, dtype=np.uint8), casting="unsafe")
    np.maximum(view, scaled, out=view)


def paint_group(costs: np.ndarray, spec: GridSpec, hull: BaseGeometry, params: SocialParams) -> Window | None:
    """Max a group's zone cost and its fall-off into ``costs`` (in place); returns the window it reaches.

    ``hull``: the group's ``zone_hull``.

    Distances within 1e-6 m of the zone edge count as inside, so rounding never drops a cell that lies in
    ``group_zone_polygon`` below ``group_cost``.
    """
    reach = params.group_margin + _reach(params.group_cost, params.group_sigma)
    x0, y0, x1, y1 = hull.bounds
    window = spec.window((x0 - reach, y0 - reach), (x1 + reach, y1 + reach))
    if window is None:
        return None
    ox, oy = (x0 + x1) / 2, (y0 + y1) / 2
    dx, dy = _local_axes(spec, window, ox, oy)
    ring, polygon = _hull_ring(hull)
    ring = ring - (ox, oy)  # as the cell offsets: relative to the hull's centre
    outside = _distance_to_hull(dx, dy, ring, polygon)
    outside -= np.float32(params.group_margin + 1e-6)
    np.maximum(outside, 0, out=outside)
    outside *= outside  # then the exponent, with a negative coefficient
    outside *= np.float32(-0.5 / params.group_sigma**2)
    _max_into(costs[window.slices], _exp(outside), params.group_cost)
    return window


def paint_body(costs: np.ndarray, spec: GridSpec, person: Person, body_radius: float) -> Window | None:
    """Mark every cell whose centre lies within ``body_radius`` of the person LETHAL (in place); returns the window."""
    r = body_radius
    window = spec.window((person.x - r, person.y - r), (person.x + r, person.y + r))
    if window is None:
        return None
    xs, ys = spec.cell_axes(window)
    view = costs[window.slices]
    view[(xs - person.x) ** 2 + (ys - person.y) ** 2 <= r**2] = LETHAL
    return window


class SocialLayer(Layer):
    """Rebuilt from the current people and groups at every update, so it never keeps stale marks.

    Combined by max with its free cells left out (``max_nonzero``): they carry no opinion, as cells outside a Nav2
    layer's bounds, so unknown space stays unknown around people. ``body_radius``: a person's body (m).
    """

    name = "social"
    combination: CombinationMethod = "max_nonzero"

    def __init__(self, spec: GridSpec, params: SocialParams | None = None, body_radius: float = 0.2) -> None:
        check_number("social layer", "body_radius", body_radius, low=0, low_open=True, unit="metres")
        super().__init__(spec)
        self.params = params or SocialParams()
        self.body_radius = float(body_radius)
        self._painted: Window | None = None  # the cells the last update may have painted

    def update(self, inputs: LayerInputs, changed: Window | None) -> Window | None:
        """Repaint the layer for the people (world frame) and groups of ``inputs``."""
        by_id = _people_by_id(inputs.people)
        hulls = [zone_hull(group, by_id) for group in inputs.groups]  # raises on a bad group before any change
        previous = self._painted
        if previous is not None:
            self.costs[previous.slices] = FREE_SPACE
        painted = [paint_group(self.costs, self.spec, hull, self.params) for hull in hulls]
        painted += [paint_person(self.costs, self.spec, person, self.params) for person in inputs.people]
        painted += [paint_body(self.costs, self.spec, person, self.body_radius) for person in inputs.people]
        self._painted = union(*painted)
        return union(previous, self._painted)
