"""YOLO-pose decoding, NMS and mapping back to image pixels on tiny ONNX models with the export's signature."""

from __future__ import annotations

import numpy as np
import pytest

from sid.perception.pose import YoloPose, load_pose_estimator
from sid.perception.pose.contracts import PoseModelError
from tests.pose_models import build_model_with_output, build_yolo_pose_model, yolo_candidate

IMAGE = np.zeros((480, 640, 3), np.uint8)  # in 256x256: scale 0.4, 32 px bands above and below


def _kpts(x: float, y: float) -> np.ndarray:
    return np.tile([x, y], (17, 1))


@pytest.fixture
def candidates() -> np.ndarray:
    """Normalised candidates: A; A' overlapping A (IoU 0.87) with a lower score; B apart; C below threshold."""
    return np.stack(
        [
            yolo_candidate([0.25, 0.5, 0.2, 0.5], 0.9, _kpts(0.25, 0.375)),  # A
            yolo_candidate([0.26, 0.51, 0.2, 0.5], 0.8, _kpts(0.9, 0.9)),  # A'
            yolo_candidate([0.75, 0.5, 0.1, 0.3], 0.7, _kpts(0.75, 0.5), visibility=0.4),  # B
            yolo_candidate([0.5, 0.2, 0.1, 0.1], 0.1, _kpts(0.5, 0.2)),  # C
        ],
        axis=1,
    )


def test_nms_keeps_the_best_of_overlapping_candidates(tmp_path, candidates):
    estimator = load_pose_estimator(build_yolo_pose_model(tmp_path / "y.onnx", candidates))
    assert isinstance(estimator, YoloPose) and estimator.normalised and estimator.layout == "nhwc"
    found = estimator(IMAGE)
    assert [round(d.box_score, 3) for d in found] == [0.9, 0.7]
    a, b = found
    # A: centre (0.25, 0.5) x 256 = (64, 128) input edge px -> (160, 240) image edge -> (159.5, 239.5);
    # size 0.2 x 0.5 of 256 px = 51.2 x 128 input px = 128 x 320 image px.
    np.testing.assert_allclose(a.box, [95.5, 79.5, 223.5, 399.5], atol=1e-3)
    # keypoints (0.25, 0.375): y 96 input px -> (96 - 32) / 0.4 = 160 image edge px.
    np.testing.assert_allclose(a.keypoints, _kpts(159.5, 159.5), atol=1e-3)
    np.testing.assert_allclose(a.scores, 0.9, atol=1e-6)
    np.testing.assert_allclose(b.scores, 0.4, atol=1e-6)
    np.testing.assert_allclose(b.keypoints, _kpts(479.5, 239.5), atol=1e-3)


def test_iou_and_score_thresholds_are_options(tmp_path, candidates):
    path = build_yolo_pose_model(tmp_path / "y.onnx", candidates)
    assert len(load_pose_estimator(path, iou_threshold=0.9)(IMAGE)) == 3  # A' overlaps A by IoU 0.87 < 0.9
    assert len(load_pose_estimator(path, score_threshold=0.05)(IMAGE)) == 3  # C joins, A' still suppressed
    assert load_pose_estimator(path, score_threshold=0.95)(IMAGE) == []
    with pytest.raises(ValueError, match="iou_threshold"):
        load_pose_estimator(path, iou_threshold=0.0)


@pytest.mark.parametrize("layout", ["nhwc", "nchw"])
def test_pixel_and_normalised_exports_and_both_layouts_decode_alike(tmp_path, candidates, layout):
    reference = load_pose_estimator(build_yolo_pose_model(tmp_path / "n.onnx", candidates))(IMAGE)
    in_pixels = candidates.copy()
    in_pixels[[0, 1, 2, 3]] *= 256  # box in input pixels
    in_pixels[5:].reshape(17, 3, -1)[:, :2] *= 256  # keypoints x, y in input pixels
    estimator = load_pose_estimator(build_yolo_pose_model(tmp_path / "p.onnx", in_pixels, layout=layout))
    assert not estimator.normalised and estimator.layout == layout
    found = estimator(IMAGE)
    assert len(found) == len(reference)
    for got, want in zip(found, reference, strict=True):
        np.testing.assert_allclose(got.keypoints, want.keypoints, atol=1e-3)
        np.testing.assert_allclose(got.box, want.box, atol=1e-3)


def test_non_square_input_and_boxes_clipped_to_the_image(tmp_path):
    edge = yolo_candidate([0.0, 0.5, 0.2, 0.5], 0.9, _kpts(0.0, 0.5))  # centred on the left edge
    estimator = load_pose_estimator(build_yolo_pose_model(tmp_path / "y.onnx", edge[:, None], input_hw=(192, 256)))
    assert estimator.input_size == (192, 256)
    (person,) = estimator(IMAGE)  # 640x480 fills 256x192 exactly: scale 0.4, no bands
    assert person.box[0] == -0.5  # clipped to the image's outer edge
    np.testing.assert_allclose(person.keypoints[0], [-0.5, 239.5], atol=1e-3)


def test_no_candidate_above_threshold_gives_no_people(tmp_path):
    estimator = load_pose_estimator(build_yolo_pose_model(tmp_path / "y.onnx", np.zeros((56, 30))))
    assert estimator(IMAGE) == []


def test_dynamic_size_defaults_to_640_and_accepts_a_choice(tmp_path, candidates):
    path = build_yolo_pose_model(tmp_path / "y.onnx", candidates, input_hw=(None, None), layout="nchw")
    assert load_pose_estimator(path).input_size == (640, 640)
    assert load_pose_estimator(path, input_size=(384, 512)).input_size == (384, 512)
    with pytest.raises(ValueError, match="multiples of 32"):
        load_pose_estimator(path, input_size=500)


@pytest.mark.parametrize(
    ("declared", "match"),
    [
        ([1, "n", "c"], r"output of shape \[1, 30, 56\].*answers \[1, 56, N\]"),  # checked when loaded
        ([1, "n", 56], r"output \[1, None, 56\] looks transposed"),  # refused by the contract
    ],
)
def test_transposed_output_is_refused_naming_its_shape(tmp_path, declared, match):
    transposed = np.zeros((1, 30, 56), np.float32)  # [1, N, 56]: reshaped to [56, N] it would be garbage
    path = build_model_with_output(tmp_path / "t.onnx", transposed, declared, [1, 256, 256, 3])
    with pytest.raises(PoseModelError, match=match):
        load_pose_estimator(path)


@pytest.mark.parametrize(("input_hw", "layout"), [((256, None), "nchw"), ((None, 320), "nhwc")])
def test_half_dynamic_input_is_refused_naming_its_sides(tmp_path, candidates, input_hw, layout):
    path = build_yolo_pose_model(tmp_path / "y.onnx", candidates, input_hw=input_hw, layout=layout)
    with pytest.raises(PoseModelError, match="one side fixed and the other dynamic"):
        load_pose_estimator(path, input_size=(256, 320))
