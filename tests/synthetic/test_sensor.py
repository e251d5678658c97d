"""``SyntheticCamera``'s options and the ground truth it hands out."""

from __future__ import annotations

import math

import pytest

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
