"""``SyntheticCamera``'s options and the ground truth it hands out."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sid.synthetic.layouts import layout
from sid.synthetic.sensor import D435I_DEPTH, SyntheticCamera, d435i_calibration


@pytest.mark.parametrize("focal", [0.0, -420.0, math.nan, math.inf, "420"])
def test_sensor_focal_px_must_be_a_positive_finite_number(focal) -> None:
    with pytest.raises(ValueError, match="synthetic camera: sensor_focal_px must be a positive number of pixels"):
        SyntheticCamera(registered=True, sensor_focal_px=focal)


def test_sensor_focal_px_and_registered_defaults_and_contradictions() -> None:
    assert SyntheticCamera(registered=True).sensor_focal_px == D435I_DEPTH.fx
    assert SyntheticCamera(registered=True, sensor_focal_px=380.0).sensor_focal_px == 380.0
    assert SyntheticCamera(sensor_focal_px=D435I_DEPTH.fx).sensor_focal_px == D435I_DEPTH.fx  # agrees: accepted
    with pytest.raises(ValueError, match="sensor_focal_px 380.0 contradicts the calibration's depth fx 420.0"):
        SyntheticCamera(sensor_focal_px=380.0)  # unregistered: the depth intrinsics' fx drives the noise
    with pytest.raises(ValueError, match="registered=True contradicts the calibration, whose depth is not registered"):
        SyntheticCamera(calibration=d435i_calibration(), registered=True)
    with pytest.raises(ValueError, match="registered=False contradicts the calibration, whose depth is registered"):
        SyntheticCamera(calibration=d435i_calibration(registered=True), registered=False)
    assert SyntheticCamera(calibration=d435i_calibration(registered=True), registered=True).calibration.depth is None


def test_frames_and_detections_do_not_share_arrays_with_the_kept_render() -> None:
    """The camera keeps a still scene's render for the next frames: changing one frame's truth (or a TruthPose
    detection made from it) must not change another frame's."""
    from sid.synthetic.noise import KeypointNoise
    from sid.synthetic.pose import TruthPose

    camera = SyntheticCamera(shaded_color=False, keypoint_noise=KeypointNoise(0.0, 0.0))
    scene = layout("S3")
    first = camera.capture(scene, index=0).truth.people[0]
    reference = SyntheticCamera(shaded_color=False, keypoint_noise=KeypointNoise(0.0, 0.0)).capture(scene, index=3)
    reference = reference.truth.people[0]
    detection = TruthPose()(camera.capture(scene, index=2))[0]
    for array in (first.keypoints_world, first.keypoints_px, first.box, detection.box, detection.keypoints):
        array[:] = -1.0
    first.visible[:] = False
    first.self_occluded[:] = True
    later = camera.capture(scene, index=3).truth.people[0]
    for name in ("keypoints_world", "keypoints_px", "visible", "self_occluded", "box", "observed_px"):
        np.testing.assert_array_equal(getattr(later, name), getattr(reference, name), err_msg=name)
