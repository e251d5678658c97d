"""The real pose models in ../shared/models on the real five-people frame (skipped when ../shared is absent)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from sid.perception.keypoints import KP, LEFT_SHOULDER, RIGHT_SHOULDER
from sid.perception.overlay import draw_detections
from sid.perception.pose import load_pose_estimator
from tests.conftest import shared_path

YOLO = ("models", "yolo11n-pose-256.onnx")
MOVENET = ("models", "movenet_singlepose_lightning_4.onnx")
FIVE_PEOPLE = ("data", "rgbd", "five_people", "color.png")


@pytest.fixture(scope="module")
def color() -> np.ndarray:
    return cv2.cvtColor(cv2.imread(str(shared_path(*FIVE_PEOPLE))), cv2.COLOR_BGR2RGB)


@pytest.fixture(scope="module")
def yolo_people(color):
    estimator = load_pose_estimator(shared_path(*YOLO))
    assert estimator.contract == "yolo_pose" and estimator.input_size == (256, 256) and estimator.normalised
    return estimator(color)


def _on_body(keypoints: np.ndarray, box: np.ndarray) -> None:
    """Shoulders and hips inside the person's box, shoulders above hips, and (backs to the camera) the person's
    left side on the image's left."""
    torso = keypoints[[LEFT_SHOULDER, RIGHT_SHOULDER, KP["left_hip"], KP["right_hip"]]]
    assert np.all((torso[:, 0] >= box[0]) & (torso[:, 0] <= box[2]) & (torso[:, 1] >= box[1]) & (torso[:, 1] <= box[3]))
    assert max(torso[0, 1], torso[1, 1]) < min(torso[2, 1], torso[3, 1])
    assert torso[0, 0] < torso[1, 0] and torso[2, 0] < torso[3, 0]


def test_yolo_pose_finds_the_five_people(yolo_people, color):
    assert len(yolo_people) == 5
    assert min(d.box_score for d in yolo_people) > 0.5
    centres = sorted((d.box[0] + d.box[2]) / 2 for d in yolo_people)
    assert np.min(np.diff(centres)) > 50  # five distinct people, not duplicates NMS missed
    for person in yolo_people:
        assert person.box[3] - person.box[1] > 300  # standing people 1.8-3 m away fill most of 480 px
        _on_body(person.keypoints, person.box)


def test_movenet_singlepose_on_each_crop_puts_shoulders_and_hips_on_the_body(yolo_people, color):
    estimator = load_pose_estimator(shared_path(*MOVENET))
    assert estimator.contract == "movenet_singlepose" and estimator.input_size == (192, 192)
    boxes = np.array([d.box for d in yolo_people])
    found = estimator.estimate_in_boxes(color, boxes)
    assert len(found) == 5
    for person, box in zip(found, boxes, strict=True):
        np.testing.assert_array_equal(person.box, box)
        assert person.box_score > estimator.score_threshold
        assert person.scores[[LEFT_SHOULDER, RIGHT_SHOULDER, KP["left_hip"], KP["right_hip"]]].min() > 0.3
        _on_body(person.keypoints, box)
        # Agrees with YOLO's own torso keypoints to within a tenth of the person's height.
        yolo = next(d for d in yolo_people if np.array_equal(d.box, box))
        torso = [LEFT_SHOULDER, RIGHT_SHOULDER, KP["left_hip"], KP["right_hip"]]
        assert np.abs(person.keypoints[torso] - yolo.keypoints[torso]).max() < 0.1 * (box[3] - box[1])


def test_overlay_of_the_real_frame(yolo_people, color, tmp_path):
    picture = draw_detections(color, yolo_people)
    h, w = color.shape[:2]
    assert picture.shape[1:] == color.shape[1:] and picture.shape[0] > h and picture.dtype == np.uint8  # and a legend
    assert np.count_nonzero(np.any(picture[:h] != color[..., ::-1], axis=-1)) > 5000  # skeletons and boxes drawn
    assert cv2.imwrite(str(tmp_path / "five_people_pose.png"), picture)


def test_a_model_that_fits_its_contract_but_fails_when_run_is_named_at_load(tmp_path):
    """YOLO11n-pose-256 with its height and width declared dynamic runs at 640 x 640, where its fixed Reshape fails:
    sid detect, sid model compare and sid simulate ended in onnxruntime's traceback (exit 1)."""
    import onnx

    from sid.perception.pose import PoseModelError

    model = onnx.load(str(shared_path(*YOLO)))
    dims = model.graph.input[0].type.tensor_type.shape.dim
    for k, name in ((1, "H"), (2, "W")):
        dims[k].ClearField("dim_value")
        dims[k].dim_param = name
    onnx.save(model, str(tmp_path / "dynamic.onnx"))
    with pytest.raises(PoseModelError, match=r"dynamic.onnx: the model fits the yolo_pose contract but fails when run"):
        load_pose_estimator(tmp_path / "dynamic.onnx")
    assert load_pose_estimator(tmp_path / "dynamic.onnx", input_size=256).input_size == (256, 256)
