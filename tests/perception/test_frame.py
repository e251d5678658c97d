"""The Frame record refuses what would lift people to wrong places."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sid.perception.camera import Intrinsics
from sid.perception.frame import MAX_MEDIAN_DEPTH_M, Frame
from sid.perception.robot_pose import RobotPose
from sid.synthetic.sensor import d435i_calibration

REGISTERED = d435i_calibration(registered=True)
UNREGISTERED = d435i_calibration(registered=False)


def _frame(calibration=REGISTERED, depth_m: float = 2.0) -> Frame:
    color, depth = calibration.color, calibration.depth or calibration.color
    return Frame(
        0,
        np.zeros((color.height, color.width, 3), dtype=np.uint8),
        np.full((depth.height, depth.width), depth_m, dtype=np.float32),
        calibration,
    )


def test_a_frame_that_matches_its_calibration_is_kept_as_given() -> None:
    for calibration in (REGISTERED, UNREGISTERED):
        frame = _frame(calibration)
        again = Frame(1, frame.color, frame.depth, calibration, 0.1)
        assert again.color is frame.color and again.depth is frame.depth  # checked, not copied
        bgr = np.ascontiguousarray(frame.color[..., ::-1])
        view = Frame(2, bgr[..., ::-1], frame.depth, calibration, 0.2)
        assert view.color.base is bgr  # a view stays a view: copying it cost 8 ms a frame at 1080p
    moved = dataclasses.replace(_frame(), robot_pose=RobotPose(1.0, 2.0, 0.5), timestamp=np.float64(3.5))
    assert moved.robot_pose == RobotPose(1.0, 2.0, 0.5)


def test_a_colour_image_of_another_size_than_the_calibration_is_refused() -> None:
    frame = _frame()
    half = np.zeros((frame.color.shape[0] // 2, frame.color.shape[1] // 2, 3), dtype=np.uint8)
    with pytest.raises(ValueError, match=r"colour image is 640x360 but the calibration's colour intrinsics are"):
        dataclasses.replace(frame, color=half)


def test_a_depth_image_of_another_size_or_type_is_refused() -> None:
    frame = _frame(UNREGISTERED)
    with pytest.raises(ValueError, match="frame: depth image is 1280x720 but the calibration says 848x480"):
        dataclasses.replace(frame, depth=np.zeros(frame.color.shape[:2], dtype=np.float32))
    with pytest.raises(ValueError, match="frame: depth must be float metres, got dtype uint16"):
        dataclasses.replace(frame, depth=np.zeros(frame.depth.shape, dtype=np.uint16))


def test_depth_in_millimetres_given_as_floats_is_refused_even_without_people() -> None:
    _frame(depth_m=MAX_MEDIAN_DEPTH_M * 0.9)
    with pytest.raises(ValueError, match=r"frame: depth reads 2000 m at the median.*multiply by the depth scale"):
        _frame(depth_m=2000.0)
    frame = _frame(depth_m=0.0)  # no reading at all: nothing to tell the unit from
    assert not frame.depth.any()


def test_a_calibration_pose_or_timestamp_of_another_type_is_refused() -> None:
    frame = _frame()
    intrinsics: Intrinsics = REGISTERED.color
    with pytest.raises(TypeError, match="frame: calibration must be a sid.perception.camera.Calibration, got Intr"):
        dataclasses.replace(frame, calibration=intrinsics)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="frame: robot_pose must be .*RobotPose or None, got tuple"):
        dataclasses.replace(frame, robot_pose=(0.0, 0.0, 0.0))  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="frame: timestamp must be a finite number of seconds, got '0.1'"):
        dataclasses.replace(frame, timestamp="0.1")  # type: ignore[arg-type]
