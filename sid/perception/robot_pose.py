"""The robot's pose in the map and the frames sid's outputs are given in (REP-105 names).

``map``: the fixed world frame of a deployment (a scenario's frame, a SLAM map). ``base_footprint``: the robot's
ground frame, x forward, y left, z up, origin on the ground below the robot's centre. The pipeline lifts people
into ``base_footprint`` through the camera mount (``sid.perception.mount``) and, when the frame carries the robot's
pose, moves them into ``map`` (``person_to_map``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sid.checks import check_numbers
from sid.perception.people import Person

__all__ = ["BASE_FRAME", "MAP_FRAME", "RobotPose"]

MAP_FRAME = "map"
BASE_FRAME = "base_footprint"


@dataclass(frozen=True)
class RobotPose:
    """Pose of ``base_footprint`` in the map: position (x, y) in metres, heading yaw in radians (CCW from map +x)."""

    x: float
    y: float
    yaw: float

    def __post_init__(self) -> None:
        check_numbers("robot pose", self, ("x", "y", "yaw"))

    @property
    def rotation(self) -> np.ndarray:
        """2x2 rotation taking base_footprint vectors to map vectors."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return np.array([[c, -s], [s, c]])

    def to_map(self, points: np.ndarray) -> np.ndarray:
        """(N, 2) base_footprint points (m) -> (N, 2) map points (m)."""
        return np.asarray(points, dtype=float).reshape(-1, 2) @ self.rotation.T + np.array([self.x, self.y])

    def to_base(self, points: np.ndarray) -> np.ndarray:
        """(N, 2) map points (m) -> (N, 2) base_footprint points (m)."""
        return (np.asarray(points, dtype=float).reshape(-1, 2) - np.array([self.x, self.y])) @ self.rotation

    def yaw_to_map(self, yaw: float) -> float:
        """A heading in base_footprint (rad) -> the same heading in the map, wrapped to (-pi, pi]."""
        wrapped = math.remainder(yaw + self.yaw, math.tau)  # in [-pi, pi]: -pi is the same heading as pi
        return math.pi if wrapped == -math.pi else wrapped

    def person_to_map(self, person: Person) -> Person:
        """The same person with position, facing and 3D keypoints moved from base_footprint to the map (heights
        unchanged)."""
        (x, y), keypoints = self.to_map(person.position)[0], person.keypoints_world
        if keypoints is not None:
            keypoints = np.column_stack([self.to_map(keypoints[:, :2]), keypoints[:, 2]])
        theta = None if person.theta is None else self.yaw_to_map(person.theta)
        return Person(person.id, float(x), float(y), theta, person.orientation_quality, keypoints)
