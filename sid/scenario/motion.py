"""Scripted motion on the ground: a start pose, waypoints walked in order at a constant speed (map frame).

Used for the people and the robot of a scenario (``people[i].path``, ``robot.path``; docs/scenario.md). A mover
stands at its start pose until ``start_time``, then walks straight from waypoint to waypoint at ``speed``, facing
its direction of travel, and stands at the last waypoint facing the direction of the last leg. Metres, seconds,
radians (yaw counter-clockwise from map +x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import pairwise

from sid.checks import check_number, check_numbers
from sid.errors import InputError

__all__ = ["MotionState", "Trajectory"]


@dataclass(frozen=True)
class MotionState:
    """Where a mover is at one time: position (m), heading yaw (rad, None when unknown), velocity (m/s)."""

    x: float
    y: float
    yaw: float | None
    vx: float = 0.0
    vy: float = 0.0

    @property
    def moving(self) -> bool:
        """True while walking along the path (between ``start_time`` and the arrival at the last waypoint)."""
        return self.vx != 0.0 or self.vy != 0.0


@dataclass(frozen=True)
class Trajectory:
    """A start pose (x, y in m; yaw in rad, None = unknown) and the waypoints ``path`` walked after it.

    speed: m/s along the path. start_time: s before which the mover stands at the start pose. Consecutive points
    (the start included) must differ. Without a path the mover stands still; with one and no yaw, it faces its
    first leg while waiting.
    """

    x: float
    y: float
    yaw: float | None = None
    path: tuple[tuple[float, float], ...] = ()
    speed: float = 1.2
    start_time: float = 0.0

    def __post_init__(self) -> None:
        check_numbers("trajectory", self, ("x", "y"), unit="metres")
        if self.yaw is not None:
            check_number("trajectory", "yaw", self.yaw, unit="radians")
        check_number("trajectory", "speed", self.speed, low=0, low_open=True, unit="metres per second")
        check_number("trajectory", "start_time", self.start_time, low=0, unit="seconds")
        previous = (self.x, self.y)
        for i, point in enumerate(self.path):
            if len(point) != 2:
                raise InputError(f"trajectory: path[{i}] must be an (x, y) pair, got {point}")
            check_number("trajectory", f"path[{i}][0]", point[0], unit="metres")
            check_number("trajectory", f"path[{i}][1]", point[1], unit="metres")
            if tuple(point) == previous:
                raise InputError(f"trajectory: path[{i}] {tuple(point)} repeats the point before it")
            previous = (point[0], point[1])

    @property
    def duration(self) -> float:
        """Time (s) from the start of the walk to the arrival at the last waypoint (0 without a path)."""
        return sum(self._legs()) / self.speed

    @property
    def end_time(self) -> float:
        """Time (s) at which the mover stops for good: ``start_time + duration``, or 0 without a path."""
        return self.start_time + self.duration if self.path else 0.0

    def at(self, t: float) -> MotionState:
        """The pose and velocity at time ``t`` (s; before 0 counts as 0)."""
        points = ((self.x, self.y), *self.path)
        if not self.path or t < self.start_time:
            yaw = self.yaw if self.yaw is not None or not self.path else _heading(points[0], points[1])
            return MotionState(self.x, self.y, yaw)
        travelled = (t - self.start_time) * self.speed
        for (a, b), length in zip(pairwise(points), self._legs(), strict=True):
            if travelled < length:
                ux, uy = (b[0] - a[0]) / length, (b[1] - a[1]) / length
                return MotionState(
                    a[0] + ux * travelled, a[1] + uy * travelled, math.atan2(uy, ux), ux * self.speed, uy * self.speed
                )
            travelled -= length
        return MotionState(points[-1][0], points[-1][1], _heading(points[-2], points[-1]))

    def _legs(self) -> list[float]:
        points = ((self.x, self.y), *self.path)
        return [math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in pairwise(points)]


def _heading(a: tuple[float, float], b: tuple[float, float]) -> float:
    return math.atan2(b[1] - a[1], b[0] - a[0])
