"""Scenario records: a map, obstacles, people and a robot task, in the world frame (metres, radians).

The file format (JSON or YAML) and its loader live here too; see README "Scenario file".
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from costmap.grid import GridSpec
from sid.groups import GroupParams
from sid.people import Person


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


@dataclass(frozen=True)
class RobotSpec:
    """Start and goal poses (x, y, yaw) and the radius of the robot's disc footprint."""

    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    radius: float = 0.25


@dataclass(frozen=True)
class LidarSpec:
    """A simulated 2D LiDAR at the robot's start pose: beam count, max range (m), scan height (m)."""

    beams: int = 720
    range_max: float = 10.0
    height: float = 0.3


@dataclass
class Scenario:
    name: str
    grid: GridSpec
    robot: RobotSpec
    obstacles: list[Obstacle] = field(default_factory=list)
    people: list[Person] = field(default_factory=list)
    lidar: LidarSpec = field(default_factory=LidarSpec)
    static_map: Path | None = None
    group_params: GroupParams = field(default_factory=GroupParams)
