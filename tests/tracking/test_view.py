"""The camera's field of view on the ground (``camera_fov``, ``camera_view_cone``) for cameras facing any way."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sid.perception.camera import Calibration
from sid.perception.mount import CameraMount
from sid.synthetic.sensor import D435I_COLOR
from sid.tracking import camera_fov, camera_view_cone

CALIBRATION = Calibration(D435I_COLOR)
OPENING = 2 * math.atan(640 / 910)  # the D435i colour image's horizontal opening at its principal row


@pytest.mark.parametrize("yaw", [0.0, math.pi / 2, -math.pi / 2, 2.5, math.pi, -math.pi, -2.9])
def test_the_axis_is_the_mount_yaw_and_the_opening_the_lens_whichever_way_the_camera_faces(yaw):
    axis, fov = camera_fov(CALIBRATION, CameraMount(yaw=yaw))
    assert fov == pytest.approx(OPENING)
    assert math.remainder(axis - yaw, math.tau) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize(
    ("yaw", "ahead"),
    [(math.pi, (-3.0, 0.0)), (-math.pi, (-3.0, 0.0)), (math.pi / 2, (0.0, 3.0)), (-2.9, (-3.0, -0.7))],
)
def test_a_rear_or_side_camera_sees_where_it_faces_and_not_in_front_of_the_robot(yaw, ahead):
    cone = camera_view_cone(CALIBRATION, CameraMount(yaw=yaw))
    inside = cone.contains(np.array([ahead, (3.0, 0.0), (3.0, 0.5)]))
    assert inside.tolist() == [True, False, False]
