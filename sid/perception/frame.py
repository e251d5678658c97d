"""The record every source yields: one colour image, one depth image and the calibration that links them."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sid.checks import check_number, check_whole
from sid.errors import InputError, InputTypeError
from sid.perception.align import check_depth_image
from sid.perception.camera import Calibration
from sid.perception.pose.base import validate_color_image
from sid.perception.robot_pose import RobotPose

__all__ = ["MAX_MEDIAN_DEPTH_M", "Frame"]

MAX_MEDIAN_DEPTH_M = 100.0
"""A depth image whose typical valid reading is farther than this (m) is not in metres: an RGB-D camera reads up to
about 10 m (a uint16 image in millimetres tops out at 65.5 m), so it is millimetres given as floats."""
# Every n-th pixel along each axis is enough to tell millimetres from metres (~1200 readings at 640x480).
_UNIT_SAMPLE = 16


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

    def __post_init__(self) -> None:
        """Refuse what would lift people to wrong places: a colour or depth image of another size than the
        calibration says, depth that is not float metres, a calibration or robot pose of another type."""
        calibration = self.calibration
        if not isinstance(calibration, Calibration):
            raise InputTypeError(
                f"frame: calibration must be a sid.perception.camera.Calibration, got {type(calibration).__name__}"
            )
        check_whole("frame", "index", self.index)
        check_number("frame", "timestamp", self.timestamp, unit="seconds")
        if self.robot_pose is not None and not isinstance(self.robot_pose, RobotPose):
            raise InputTypeError(
                f"frame: robot_pose must be a sid.perception.robot_pose.RobotPose or None, got "
                f"{type(self.robot_pose).__name__}"
            )
        validate_color_image(self.color, "frame")  # not copied: a frame's colour image may be a view
        height, width = self.color.shape[:2]
        color = calibration.color
        if (width, height) != (color.width, color.height):
            raise InputError(
                f"frame: colour image is {width}x{height} but the calibration's colour intrinsics are "
                f"{color.width}x{color.height} (the intrinsics of another stream or resolution?)"
            )
        depth = check_depth_image(self.depth, calibration.depth or color, "frame")
        sample = depth[::_UNIT_SAMPLE, ::_UNIT_SAMPLE]
        readings = sample[(sample > 0) & np.isfinite(sample)]
        if readings.size and (typical := float(np.median(readings))) > MAX_MEDIAN_DEPTH_M:
            raise InputError(
                f"frame: depth reads {typical:.6g} m at the median, more than {MAX_MEDIAN_DEPTH_M:g} m: depth must be "
                "float metres (millimetres? multiply by the depth scale, e.g. 0.001)"
            )
