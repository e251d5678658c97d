"""Social-navigation metrics of a path, in the conventions of the HuNavSim and SEAN benchmarks.

All inputs are in the world frame (metres). Distances to people are to their centres. Band fractions count path
samples spaced at most ``spacing`` apart along the path (every vertex included). Group zones are
``costmap.layers.social.group_zone_polygon``, the same polygons the social layer paints, so "the path stays out of the
zone" and "the planner avoided the zone's cost" mean the same thing.

Fixed keys of ``path_metrics`` (others may be added): success, path_length_m, planning_time_s,
min_person_distance_m, ospace_intrusion_m, crosses_group, personal_space_fraction. ``personal_space_fraction`` is
the fraction of samples within Hall's personal distance (closer than 1.2 m to someone: the intimate and personal
bands together); ``band_fractions`` gives the three bands separately.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from itertools import combinations
from typing import TYPE_CHECKING, Any

import numpy as np
from shapely.geometry import LineString, Point
from shapely.ops import unary_union

from costmap.grid import LETHAL, MAX_NON_OBSTACLE, NO_INFORMATION, Costmap2D
from costmap.layers.social import group_zone_polygon
from planner.validity import interpolate
from sid.errors import InputError
from sid.perception.group import Group
from sid.perception.people import Person

if TYPE_CHECKING:
    from planner.facade import PlanResult

__all__ = [
    "FIXED_KEYS",
    "HALL_BANDS",
    "PERSONAL_DISTANCE_M",
    "SAMPLE_SPACING_M",
    "crosses_group",
    "group_zones",
    "heading_change",
    "min_distance_to_points",
    "nearest_distances",
    "path_length",
    "path_metrics",
    "result_metrics",
]

HALL_BANDS: dict[str, tuple[float, float]] = {"intimate": (0.0, 0.45), "personal": (0.45, 1.2), "social": (1.2, 3.6)}
PERSONAL_DISTANCE_M = 1.2
SAMPLE_SPACING_M = 0.02
"""Largest gap (m) between the path samples that the band fractions and ``personal_space_fraction`` count."""


def path_length(path: np.ndarray) -> float:
    """Sum of segment lengths (m) of a polyline (N, 2)."""
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    return float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0


def heading_change(path: np.ndarray) -> float:
    """Cumulative absolute heading change (rad) along a polyline, zero-length segments skipped."""
    d = np.diff(np.asarray(path, dtype=float).reshape(-1, 2), axis=0)
    d = d[np.hypot(d[:, 0], d[:, 1]) > 1e-9]
    if len(d) < 2:
        return 0.0
    heading = np.arctan2(d[:, 1], d[:, 0])
    turn = (np.diff(heading) + np.pi) % (2 * np.pi) - np.pi
    return float(np.abs(turn).sum())


def nearest_distances(samples: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(N,) distance (m) from each of ``samples`` (N, 2) to the nearest of ``points`` (M, 2); inf when M = 0."""
    samples = np.asarray(samples, dtype=float).reshape(-1, 2)
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(points) == 0:
        return np.full(len(samples), math.inf)
    return np.hypot(*(samples[:, None, :] - points[None]).transpose(2, 0, 1)).min(axis=1)


def min_distance_to_points(path: np.ndarray, points: np.ndarray) -> float:
    """Exact smallest distance (m) between a polyline (N, 2) and points (M, 2); inf when there are no points."""
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(points) == 0 or len(path) == 0:
        return math.inf
    if len(path) == 1:
        return float(np.hypot(*(points - path[0]).T).min())
    a, b = path[:-1], path[1:]
    ab = b - a
    length2 = np.maximum((ab**2).sum(axis=1), 1e-18)
    t = np.clip(((points[:, None, :] - a) * ab).sum(axis=2) / length2, 0.0, 1.0)
    nearest = a + t[..., None] * ab
    return float(np.hypot(*(points[:, None, :] - nearest).transpose(2, 0, 1)).min())


def group_zones(people: Sequence[Person], groups: Sequence[Group]) -> list:
    """The interaction-zone polygons of the groups (shapely), as the social layer paints them."""
    return [group_zone_polygon(group, people) for group in groups]


def crosses_group(path: np.ndarray, people: Sequence[Person], groups: Sequence[Group]) -> bool:
    """Whether the path crosses the segment between any two members of a group ("relation disturbance")."""
    if len(path) < 2:
        return False
    line = LineString(path)
    by_id = {p.id: p for p in people}
    for group in groups:
        for i, j in combinations(group.members, 2):
            if line.intersects(LineString([(by_id[i].x, by_id[i].y), (by_id[j].x, by_id[j].y)])):
                return True
    return False


def path_metrics(
    path: np.ndarray,
    people: Sequence[Person],
    groups: Sequence[Group],
    costmap: Costmap2D | None = None,
    spacing: float = SAMPLE_SPACING_M,
) -> dict[str, Any]:
    """Geometry and social metrics of a successful path (N >= 1, world frame).

    With ``costmap``: ``cost_integral`` = integral of c / 252 ds over the graded cost c (0..252; unknown counts as
    252) and ``lethal_samples`` = samples whose cell is lethal there (collisions).
    """
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    if len(path) == 0 or not np.isfinite(path).all():
        raise InputError("path_metrics needs a non-empty path of finite (x, y) points")
    length = path_length(path)
    straight = float(np.hypot(*(path[-1] - path[0])))
    positions = np.array([(p.x, p.y) for p in people], dtype=float).reshape(-1, 2)
    samples = interpolate(path, spacing)
    metrics: dict = {
        "path_length_m": length,
        "length_ratio": length / straight if straight > 0 else None,
        "heading_change_rad": heading_change(path),
        "waypoints": len(path),
    }
    if len(positions):
        nearest = nearest_distances(samples, positions)
        metrics["min_person_distance_m"] = min_distance_to_points(path, positions)
        metrics["band_fractions"] = {
            name: float(((nearest >= lo) & (nearest < hi)).mean()) for name, (lo, hi) in HALL_BANDS.items()
        }
        metrics["personal_space_fraction"] = float((nearest < PERSONAL_DISTANCE_M).mean())
    else:
        metrics["min_person_distance_m"] = None
        metrics["band_fractions"] = dict.fromkeys(HALL_BANDS, 0.0)
        metrics["personal_space_fraction"] = 0.0
    zones = group_zones(people, groups)
    line = LineString(path) if len(path) > 1 else Point(path[0])
    metrics["ospace_intrusion_m"] = float(line.intersection(unary_union(zones)).length) if zones else 0.0
    metrics["crosses_group"] = crosses_group(path, people, groups)
    goal = Point(path[-1])
    metrics["goal_in_group_zone"] = any(zone.covers(goal) for zone in zones)
    if costmap is not None:
        costs = costmap.cost_at(samples)
        graded = np.where(costs == NO_INFORMATION, MAX_NON_OBSTACLE, np.minimum(costs, MAX_NON_OBSTACLE))
        mids = 0.5 * (graded[:-1] + graded[1:]) / MAX_NON_OBSTACLE
        metrics["cost_integral"] = float((mids * np.hypot(*np.diff(samples, axis=0).T)).sum())
        metrics["lethal_samples"] = int((costs == LETHAL).sum())
    return metrics


FIXED_KEYS = (
    "success",
    "path_length_m",
    "planning_time_s",
    "min_person_distance_m",
    "ospace_intrusion_m",
    "crosses_group",
    "personal_space_fraction",
)


def result_metrics(
    result: PlanResult, people: Sequence[Person], groups: Sequence[Group], costmap: Costmap2D | None = None
) -> dict[str, Any]:
    """The metrics of a plan: the planner's outcome plus ``path_metrics`` (JSON-ready; path metrics are None when
    the plan failed)."""
    outcome = {
        "success": bool(result.success),
        "planner": result.planner,
        "planning_time_s": float(result.planning_time_s),
        "solve_time_s": float(result.solve_time_s),
        "cost": float(result.cost) if result.success else None,
        "raw_cost": float(result.raw_cost) if math.isfinite(result.raw_cost) else None,
        "iterations": int(result.iterations),
        "seed": result.seed,
        "message": result.message,
    }
    if result.success:
        return outcome | path_metrics(result.path, people, groups, costmap)
    return outcome | {key: None for key in FIXED_KEYS if key not in outcome}
