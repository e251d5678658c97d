"""A path follower for a differential-drive robot: Nav2's regulated pure pursuit, reduced to its geometry.

Each control step takes the global path (world frame, metres), the robot's pose (x, y, yaw; world frame) and its
current linear speed (m/s), and returns a velocity command (linear m/s, angular rad/s) in the robot's frame:

1. the carrot is the point ``lookahead`` metres further along the path than the path point nearest the robot, with
   the lookahead scaled by speed (``lookahead_time_s``) and clamped to [``min_lookahead_m``, ``max_lookahead_m``];
2. when the carrot lies more than ``rotate_to_heading_rad`` off the robot's heading, the robot turns in place
   towards it (Nav2's ``use_rotate_to_heading``);
3. otherwise it drives the pure-pursuit arc through the carrot, curvature k = 2 y / L^2 (y: the carrot's lateral
   offset in the robot's frame, L its distance), at ``max_speed`` reduced on tight arcs (turning radius below
   ``regulated_min_radius_m``: speed x radius / min radius) and near the goal (within ``approach_distance_m``:
   speed x remaining / approach distance, not below ``min_approach_speed``), then scaled down so that the turn
   rate k v stays within ``max_turn_rate``.

The follower keeps no state between calls; the robot model applies acceleration limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sid.checks import check_numbers
from sid.errors import InputError

__all__ = ["Command", "FollowerParams", "follow", "nearest_arc_length", "point_at", "remaining"]


@dataclass(frozen=True)
class FollowerParams:
    """Regulated pure pursuit's parameters (metres, seconds, radians); see the module docstring."""

    max_speed: float = 0.5
    max_turn_rate: float = 1.5
    lookahead_time_s: float = 1.5
    min_lookahead_m: float = 0.3
    max_lookahead_m: float = 0.9
    rotate_to_heading_rad: float = math.radians(60.0)
    regulated_min_radius_m: float = 0.9
    approach_distance_m: float = 0.6
    min_approach_speed: float = 0.05

    def __post_init__(self) -> None:
        positive = ("max_speed", "max_turn_rate", "min_lookahead_m", "rotate_to_heading_rad", "min_approach_speed")
        check_numbers("follower", self, positive, low=0, low_open=True)
        check_numbers("follower", self, ("lookahead_time_s", "regulated_min_radius_m", "approach_distance_m"), low=0)
        if self.max_lookahead_m < self.min_lookahead_m:
            raise InputError(
                f"follower: max_lookahead_m ({self.max_lookahead_m}) is below min_lookahead_m ({self.min_lookahead_m})"
            )


@dataclass(frozen=True)
class Command:
    """A velocity command in the robot's frame: linear (m/s, forward), angular (rad/s, CCW); ``carrot``: the world
    point (x, y) it steers to."""

    linear: float
    angular: float
    carrot: tuple[float, float]


def _arc_lengths(path: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])


def nearest_arc_length(path: np.ndarray, xy: tuple[float, float]) -> tuple[float, float]:
    """(arc length along ``path`` (N, 2) of the point nearest ``xy``, distance to it), metres."""
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    point = np.asarray(xy, dtype=float)
    if len(path) == 1:
        return 0.0, float(np.hypot(*(point - path[0])))
    a, ab = path[:-1], np.diff(path, axis=0)
    length2 = np.maximum((ab**2).sum(axis=1), 1e-18)
    t = np.clip(((point - a) * ab).sum(axis=1) / length2, 0.0, 1.0)
    distance = np.hypot(*(a + t[:, None] * ab - point).T)
    i = int(np.argmin(distance))
    return float(_arc_lengths(path)[i] + t[i] * math.sqrt(length2[i])), float(distance[i])


def point_at(path: np.ndarray, s: float) -> np.ndarray:
    """The point (2,) at arc length ``s`` (m) along ``path`` (N, 2), clamped to its ends."""
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    arc = _arc_lengths(path)
    return np.array([np.interp(s, arc, path[:, 0]), np.interp(s, arc, path[:, 1])])


def follow(
    path: np.ndarray, pose: tuple[float, float, float], speed: float, params: FollowerParams = FollowerParams()
) -> Command:
    """The command that follows ``path`` (N >= 1, world frame) from ``pose`` at current ``speed`` (m/s)."""
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    if len(path) == 0 or not np.isfinite(path).all():
        raise InputError("follower: the path must hold at least one finite (x, y) point")
    x, y, yaw = (float(v) for v in pose)
    s, _ = nearest_arc_length(path, (x, y))
    total = float(_arc_lengths(path)[-1])
    lookahead = min(max(abs(speed) * params.lookahead_time_s, params.min_lookahead_m), params.max_lookahead_m)
    carrot = point_at(path, s + lookahead)
    dx, dy = carrot[0] - x, carrot[1] - y
    c, sn = math.cos(yaw), math.sin(yaw)
    ahead, left = c * dx + sn * dy, -sn * dx + c * dy  # the carrot in the robot's frame
    distance = math.hypot(ahead, left)
    target = (float(carrot[0]), float(carrot[1]))
    if distance < 1e-9:
        return Command(0.0, 0.0, target)
    bearing = math.atan2(left, ahead)
    if abs(bearing) > params.rotate_to_heading_rad:
        turn = math.copysign(min(params.max_turn_rate, 2.0 * abs(bearing)), bearing)
        return Command(0.0, turn, target)
    curvature = 2.0 * left / distance**2
    v = params.max_speed
    if abs(curvature) > 1e-9 and 1.0 / abs(curvature) < params.regulated_min_radius_m:
        v *= 1.0 / (abs(curvature) * params.regulated_min_radius_m)
    remaining = max(total - s, distance if s + lookahead >= total else 0.0)
    if params.approach_distance_m > 0 and remaining < params.approach_distance_m:
        v = min(v, max(v * remaining / params.approach_distance_m, params.min_approach_speed))
    if abs(curvature * v) > params.max_turn_rate:
        v = params.max_turn_rate / abs(curvature)
    return Command(v, curvature * v, target)


def remaining(path: np.ndarray, xy: tuple[float, float], skip: float = 0.0) -> np.ndarray:
    """The part of ``path`` (N, 2) from ``skip`` metres past the point nearest ``xy`` to its end ((M, 2), M >= 1)."""
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    s, _ = nearest_arc_length(path, xy)
    s += skip
    arc = _arc_lengths(path)
    return np.vstack([point_at(path, s)[None], path[arc > s]])
