"""Obstacle shapes of a scenario, in the world frame (metres): walls, round pillars and boxes."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class SegmentObstacle:
    """A wall: a polyline through ``points`` ((x, y), ...)."""

    points: tuple[tuple[float, float], ...]


@dataclass(frozen=True)
class CircleObstacle:
    center: tuple[float, float]
    radius: float


@dataclass(frozen=True)
class BoxObstacle:
    """An axis-aligned box from ``min`` (x, y) to ``max`` (x, y)."""

    min: tuple[float, float]
    max: tuple[float, float]


Obstacle = SegmentObstacle | CircleObstacle | BoxObstacle
