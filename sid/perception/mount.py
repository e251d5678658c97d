"""Camera optical frame <-> the robot's ground frame (``base_footprint``, REP-105).

Camera optical frame: x right, y down, z forward (metres). Robot frame: ``base_footprint`` (REP-103/105): origin on
the ground below the robot's centre, x forward, y left, z up. The mount places the camera's optical centre at
(x, y, height) in it (x, y are the same in ``base_link``, which sits straight above ``base_footprint``), turned by
``yaw`` about z and pitched down by ``tilt``. With the default mount (x = y = yaw = 0) the origin lies on the ground
directly below the camera and, with no tilt: x = z_cam, y = -x_cam, z = height - y_cam.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from sid.checks import check_number, check_numbers, check_yaws

__all__ = ["CameraMount", "MAX_MOUNT_M"]

MAX_MOUNT_M = 10.0
"""The farthest (m) a robot's camera is taken to sit from ``base_footprint``'s origin, up or sideways."""


@dataclass(frozen=True)
class CameraMount:
    """Camera pose on the robot: height of the optical centre above the ground (m), downward pitch ``tilt`` (rad),
    the optical centre's position (x, y) on ``base_footprint`` / ``base_link`` (m) and the heading ``yaw`` of its
    optical axis relative to the robot's x axis (rad, counter-clockwise).

    tilt > 0 means the camera looks down. The paper's D435i stood 0.9 m high, level, facing forward.
    """

    height: float = 0.9
    tilt: float = 0.0
    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0

    def __post_init__(self) -> None:
        # On a robot: above the ground, within MAX_MOUNT_M of the robot's origin.
        check_number("camera mount", "height", self.height, low=0, high=MAX_MOUNT_M, unit="metres")
        half_turn = np.pi / 2
        check_number("camera mount", "tilt", self.tilt, low=-half_turn, high=half_turn, low_open=True, high_open=True)
        check_numbers("camera mount", self, ("x", "y"), low=-MAX_MOUNT_M, high=MAX_MOUNT_M, unit="metres")
        check_yaws("camera mount", self, ("yaw",))

    @property
    def rotation(self) -> np.ndarray:
        """3x3 rotation whose columns are the camera's x, y, z axes in ``base_footprint``."""
        c, s = np.cos(self.tilt), np.sin(self.tilt)
        cy, sy = np.cos(self.yaw), np.sin(self.yaw)
        right, down, forward = (sy, -cy, 0.0), (-s * cy, -s * sy, -c), (c * cy, c * sy, -s)
        return np.array([right, down, forward]).T

    @property
    def position(self) -> np.ndarray:
        """(3,) the optical centre in ``base_footprint`` (m)."""
        return np.array([self.x, self.y, self.height])

    @cached_property
    def _pose(self) -> tuple[np.ndarray, np.ndarray]:
        """(rotation, position), built once per mount (read-only): the transforms run per frame."""
        rotation, position = self.rotation, self.position
        rotation.flags.writeable = position.flags.writeable = False
        return rotation, position

    def camera_to_world(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) camera-frame points -> (N, 3) ``base_footprint`` points."""
        rotation, position = self._pose
        return np.asarray(points, dtype=float).reshape(-1, 3) @ rotation.T + position

    def world_to_camera(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) ``base_footprint`` points -> (N, 3) camera-frame points."""
        rotation, position = self._pose
        return (np.asarray(points, dtype=float).reshape(-1, 3) - position) @ rotation
