"""The record every source yields: one colour image, one depth image and the calibration that links them."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sid.perception.camera import Calibration
from sid.perception.robot_pose import RobotPose

__all__ = ["Frame"]


@dataclass
class Frame:
    """One RGB-D frame.

    color: (H, W, 3) uint8 RGB. depth: (h, w) float32 metres in the depth camera's pixel grid, 0 = no reading
    (registered to colour when ``calibration.depth`` is None). timestamp: seconds. truth: ground truth that
    synthetic sources attach (None for real data). robot_pose: the pose of ``base_footprint`` in the map at
    ``timestamp`` (None when unknown: the pipeline then reports in ``base_footprint``).
    """

    index: int
    color: np.ndarray
    depth: np.ndarray
    calibration: Calibration
    timestamp: float = 0.0
    truth: Any = field(default=None, repr=False)
    robot_pose: RobotPose | None = None
