"""The social layer: people's bodies, their personal space, and the interaction zones of conversational groups.

All geometry is in the world frame (metres, radians). Costs follow Nav2 (uint8):

- body: every cell within ``body_radius`` of a person is LETHAL (254). A person is a physical obstacle, like the
  LiDAR marks this layer replaces (see ``costmap.layered``), so the inflation layer inflates bodies as any other
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

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import MultiPoint, Polygon
from shapely.geometry.polygon import orient

from costmap.grid import FREE_SPACE, LETHAL, MAX_NON_OBSTACLE, GridSpec
from sid.groups import Group
from sid.people import Person


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
        for name in ("amplitude", "group_cost"):
            value = getattr(self, name)
            if not (np.isfinite(value) and 0 <= value <= MAX_NON_OBSTACLE):
                raise ValueError(f"social.{name} must be a cost in 0..{MAX_NON_OBSTACLE}, got {value}")
        for name in ("sigma_front", "sigma_rear", "sigma_side", "sigma_unknown", "group_sigma"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"social.{name} must be a positive number of metres, got {value}")
        for name in ("group_margin", "people_clear_margin"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ValueError(f"social.{name} must be a number of metres >= 0, got {value}")


def _reach(amplitude: float, sigma: float) -> float:
    """Distance (m) at which amplitude * exp(-d^2 / 2 sigma^2) drops below 1 (the smallest non-zero cost)."""
    return sigma * float(np.sqrt(2 * np.log(amplitude))) if amplitude > 1 else 0.0


def _people_by_id(people: Sequence[Person] | Mapping[int, Person]) -> Mapping[int, Person]:
    return people if isinstance(people, Mapping) else {p.id: p for p in people}


def _zone_hull(group: Group, people: Sequence[Person] | Mapping[int, Person]) -> shapely.Geometry:
    """Convex hull (Polygon, LineString or Point) of the group's o-space vertices and its members' positions."""
    by_id = _people_by_id(people)
    missing = [m for m in group.members if m not in by_id]
    if missing:
        raise ValueError(f"group {group.members}: members {missing} are not among the people given")
    points = [(by_id[m].x, by_id[m].y) for m in group.members]
    zone = np.asarray(group.zone, dtype=float).reshape(-1, 2)
    points += [tuple(v) for v in zone]
    if not np.isfinite(np.asarray(points)).all():
        raise ValueError(f"group {group.members}: non-finite member position or zone vertex")
    return MultiPoint(points).convex_hull


def group_zone_polygon(
    group: Group, people: Sequence[Person] | Mapping[int, Person], margin: float = SocialParams.group_margin
) -> Polygon:
    """The group's interaction zone as used by the social layer and by the planner's o-space metrics.

    The convex hull of the detector's o-space polygon (``group.zone``) and the members' positions, grown by
    ``margin`` metres: it covers the o-space, the members and the space between them (the p-space). ``people``
    may be a list of persons or a mapping id -> person; every member must be there.
    """
    if not (np.isfinite(margin) and margin >= 0):
        raise ValueError(f"group zone margin must be a number of metres >= 0, got {margin}")
    grown = _zone_hull(group, people).buffer(margin, quad_segs=16) if margin > 0 else _zone_hull(group, people)
    if not isinstance(grown, Polygon) or grown.is_empty or grown.area == 0:
        raise ValueError(f"group {group.members}: the zone is degenerate (collinear points); use a margin > 0")
    return grown


def _distance_to_hull(xs: np.ndarray, ys: np.ndarray, hull: shapely.Geometry) -> np.ndarray:
    """Exact distance (m) from points to a convex hull (0 inside); hull is a Point, LineString or convex Polygon."""
    polygon = isinstance(hull, Polygon)
    ring = np.asarray(orient(hull, sign=1.0).exterior.coords if polygon else hull.coords)  # closed, CCW
    a, b = ring[:-1], ring[1:]
    if len(a) == 0:  # a single point
        return np.hypot(xs - ring[0, 0], ys - ring[0, 1])
    px, py = xs[..., None], ys[..., None]
    ex, ey = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    length2 = np.maximum(ex**2 + ey**2, 1e-18)
    t = np.clip(((px - a[:, 0]) * ex + (py - a[:, 1]) * ey) / length2, 0.0, 1.0)
    distance = np.hypot(px - (a[:, 0] + t * ex), py - (a[:, 1] + t * ey)).min(axis=-1)
    if polygon:
        cross = ex * (py - a[:, 1]) - ey * (px - a[:, 0])  # >= 0 on the inner side of every CCW edge
        distance[(cross >= 0).all(axis=-1)] = 0.0
    return distance


def paint_person(costs: np.ndarray, spec: GridSpec, person: Person, params: SocialParams) -> None:
    """Max the person's personal-space Gaussian into ``costs`` (in place; only the cells it reaches)."""
    sigma_max = params.sigma_unknown if person.theta is None else max(params.sigma_front, params.sigma_side)
    reach = _reach(params.amplitude, sigma_max)
    window = spec.window((person.x - reach, person.y - reach), (person.x + reach, person.y + reach))
    if window is None:
        return
    xs, ys = spec.cell_centres(window)
    dx, dy = xs - person.x, ys - person.y
    if person.theta is None:
        exponent = (dx**2 + dy**2) / (2 * params.sigma_unknown**2)
    else:
        c, s = np.cos(person.theta), np.sin(person.theta)
        u, v = c * dx + s * dy, -s * dx + c * dy
        su = np.where(u >= 0, params.sigma_front, params.sigma_rear)
        exponent = u**2 / (2 * su**2) + v**2 / (2 * params.sigma_side**2)
    cost = np.floor(params.amplitude * np.exp(-exponent)).astype(np.uint8)
    np.maximum(costs[window], cost, out=costs[window])


def paint_group(
    costs: np.ndarray, spec: GridSpec, group: Group, people: Mapping[int, Person], params: SocialParams
) -> None:
    """Max the group's zone cost and its fall-off into ``costs`` (in place)."""
    hull = _zone_hull(group, people)
    reach = params.group_margin + _reach(params.group_cost, params.group_sigma)
    x0, y0, x1, y1 = hull.bounds
    window = spec.window((x0 - reach, y0 - reach), (x1 + reach, y1 + reach))
    if window is None:
        return
    xs, ys = spec.cell_centres(window)
    outside = np.maximum(_distance_to_hull(xs, ys, hull) - params.group_margin, 0.0)
    cost = np.floor(params.group_cost * np.exp(-(outside**2) / (2 * params.group_sigma**2))).astype(np.uint8)
    np.maximum(costs[window], cost, out=costs[window])


def paint_body(costs: np.ndarray, spec: GridSpec, person: Person, body_radius: float) -> None:
    """Mark every cell whose centre lies within ``body_radius`` of the person LETHAL (in place)."""
    r = body_radius
    window = spec.window((person.x - r, person.y - r), (person.x + r, person.y + r))
    if window is None:
        return
    xs, ys = spec.cell_centres(window)
    view = costs[window]
    view[(xs - person.x) ** 2 + (ys - person.y) ** 2 <= r**2] = LETHAL


class SocialLayer:
    """Rebuilt from the current people and groups at every update, so it never keeps stale marks."""

    name = "social"

    def __init__(self, spec: GridSpec, params: SocialParams | None = None, body_radius: float = 0.2) -> None:
        if not (np.isfinite(body_radius) and body_radius > 0):
            raise ValueError(f"body radius must be a positive number of metres, got {body_radius}")
        self.spec = spec
        self.params = params or SocialParams()
        self.body_radius = float(body_radius)
        self.costs = np.zeros(spec.shape, dtype=np.uint8)

    def update(self, people: Sequence[Person], groups: Sequence[Group]) -> None:
        """Recompute the layer for these people (world frame) and their groups."""
        self.costs.fill(FREE_SPACE)
        by_id = _people_by_id(people)
        for group in groups:
            paint_group(self.costs, self.spec, group, by_id, self.params)
        for person in people:
            paint_person(self.costs, self.spec, person, self.params)
        for person in people:
            paint_body(self.costs, self.spec, person, self.body_radius)
