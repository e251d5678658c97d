"""Obstacle shapes of a scenario, in the world frame (metres): walls, round pillars and boxes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from shapely.geometry import LineString, Point, Polygon
from shapely.geometry.base import BaseGeometry

__all__ = ["BoxObstacle", "CircleObstacle", "Obstacle", "SegmentObstacle", "outline", "shape"]


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


def outline(obstacle: Obstacle, sides: int = 48) -> tuple[np.ndarray, bool]:
    """The shape of ``obstacle`` for drawing: world points (N, 2) and whether they close into a polygon (a box, a
    circle as a regular polygon of ``sides`` corners) or stay an open polyline (a wall)."""
    if isinstance(obstacle, BoxObstacle):
        (x0, y0), (x1, y1) = obstacle.min, obstacle.max
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float), True
    if isinstance(obstacle, CircleObstacle):
        angles = np.linspace(0.0, 2 * np.pi, sides, endpoint=False)
        centre = np.asarray(obstacle.center, dtype=float)
        return centre + obstacle.radius * np.stack([np.cos(angles), np.sin(angles)], axis=1), True
    return np.asarray(obstacle.points, dtype=float), False


def shape(obstacle: Obstacle) -> BaseGeometry:
    """``obstacle`` as a shapely geometry: a wall as a line, a box and a circle (64 segments a quarter) as areas."""
    if isinstance(obstacle, BoxObstacle):
        (x0, y0), (x1, y1) = obstacle.min, obstacle.max
        return Polygon([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
    if isinstance(obstacle, CircleObstacle):
        return Point(obstacle.center).buffer(obstacle.radius, 64)
    return LineString(obstacle.points)
