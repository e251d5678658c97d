"""The per-person 2D detection record checks its arrays' shapes exactly."""

from __future__ import annotations

import re

import numpy as np
import pytest

from sid.perception.keypoints import NUM_KEYPOINTS, PoseDetection


def test_a_detection_keeps_arrays_of_the_exact_shapes_as_floats():
    keypoints = np.arange(2 * NUM_KEYPOINTS).reshape(NUM_KEYPOINTS, 2)
    detection = PoseDetection(keypoints, [0.5] * NUM_KEYPOINTS, (1, 2, 3, 4), 0.9)
    np.testing.assert_array_equal(detection.keypoints, keypoints)
    assert detection.keypoints.dtype == float and detection.scores.shape == (NUM_KEYPOINTS,)
    assert detection.box.tolist() == [1.0, 2.0, 3.0, 4.0] and detection.box_score == 0.9


@pytest.mark.parametrize(
    ("field", "value", "shape"),
    [
        ("keypoints", np.zeros((2, NUM_KEYPOINTS)), "(2, 17)"),  # a reshape accepted it, scrambled
        ("keypoints", np.zeros((NUM_KEYPOINTS, 3)), "(17, 3)"),  # with the score column: numpy's bare error
        ("scores", np.zeros((NUM_KEYPOINTS, 1)), "(17, 1)"),
        ("box", np.zeros((2, 2)), "(2, 2)"),
        ("box", np.zeros(5), "(5,)"),
    ],
)
def test_a_wrong_shape_is_an_error_naming_the_field_and_shape(field, value, shape):
    fields = {"keypoints": np.zeros((NUM_KEYPOINTS, 2)), "scores": np.zeros(NUM_KEYPOINTS), "box": np.zeros(4)}
    message = f"pose detection: {field} must have shape .*, got {re.escape(shape)}"
    with pytest.raises(ValueError, match=message):
        PoseDetection(**(fields | {field: value}), box_score=0.5)
