"""Camera optical frame <-> world frame.

Camera optical frame: x right, y down, z forward (metres). World frame (REP-103, the paper's top view): origin on
the ground directly below the camera, x forward (the camera's depth axis projected on the ground), y left, z up.
With no tilt: world x = z_cam, world y = -x_cam, world z = height - y_cam.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sid.checks import check_number


@dataclass(frozen=True)
class CameraMount:
    """Camera pose on the robot: height of the optical centre above the ground (m) and downward pitch (rad).

    tilt > 0 means the camera looks down. The paper's D435i stood 0.9 m high, level.
    """

    height: float = 0.9
    tilt: float = 0.0

    def __post_init__(self) -> None:
        check_number("camera mount", "height", self.height, unit="metres")
        half_turn = np.pi / 2
        check_number("camera mount", "tilt", self.tilt, low=-half_turn, high=half_turn, low_open=True, high_open=True)

    @property
    def rotation(self) -> np.ndarray:
        """3x3 rotation whose columns are the camera's x, y, z axes in the world frame."""
        c, s = np.cos(self.tilt), np.sin(self.tilt)
        right, down, forward = (0.0, -1.0, 0.0), (-s, 0.0, -c), (c, 0.0, -s)
        return np.array([right, down, forward]).T

    def camera_to_world(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) camera-frame points -> (N, 3) world-frame points."""
        return np.asarray(points, dtype=float).reshape(-1, 3) @ self.rotation.T + np.array([0.0, 0.0, self.height])

    def world_to_camera(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) world-frame points -> (N, 3) camera-frame points."""
        shifted = np.asarray(points, dtype=float).reshape(-1, 3) - np.array([0.0, 0.0, self.height])
        return shifted @ self.rotation
