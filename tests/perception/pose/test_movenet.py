"""MoveNet MultiPose and SinglePose decoding on tiny ONNX models with the real models' signatures."""

from __future__ import annotations

import numpy as np
import pytest

from sid.perception.keypoints import NUM_KEYPOINTS
from sid.perception.pose import Letterbox, MoveNetMultiPose, MoveNetSinglePose, load_pose_estimator
from tests.pose_models import build_multipose_model, build_singlepose_model


def _person(y: float, x: float, score: float, box=(0.1, 0.2, 0.6, 0.4), box_score: float = 0.9) -> np.ndarray:
    """One MultiPose row: all keypoints at normalised (y, x) with ``score``, then the box (ymin, xmin, ymax, xmax)."""
    return np.concatenate([np.tile([y, x, score], NUM_KEYPOINTS), box, [box_score]])


def _red_dot(u: int, v: int, shape=(480, 640), sigma: float = 3.0, channel: int = 0) -> np.ndarray:
    """A Gaussian dot peaking (255) at pixel (u, v): after resampling, its brightest pixel is the nearest one."""
    image = np.zeros((*shape, 3), np.uint8)
    rows, cols = np.mgrid[0 : shape[0], 0 : shape[1]]
    image[..., channel] = np.round(255 * np.exp(-((cols - u) ** 2 + (rows - v) ** 2) / (2 * sigma**2)))
    return image


@pytest.fixture
def people() -> np.ndarray:
    rows = np.zeros((6, 56))
    rows[0] = _person(0.5, 0.25, 0.8, box_score=0.6)
    rows[1] = _person(0.25, 0.75, 0.7, box=(0.0, 0.5, 1.0, 1.0), box_score=0.9)
    rows[2] = _person(0.9, 0.9, 0.9, box_score=0.1)  # below the default threshold 0.2
    return rows


def test_multipose_decodes_to_exact_image_pixels_on_a_dynamic_model(tmp_path, people):
    estimator = load_pose_estimator(build_multipose_model(tmp_path / "m.onnx", people))
    assert isinstance(estimator, MoveNetMultiPose)
    assert estimator.input_size is None and estimator.input_size_for((480, 640)) == (192, 256)
    found = estimator(np.zeros((480, 640, 3), np.uint8))
    assert [round(d.box_score, 3) for d in found] == [0.9, 0.6]  # best first, the 0.1 person dropped
    # 640x480 -> 256x192, scale 0.4, no padding: normalised (y, x) = (0.25, 0.75) -> input edge coordinates
    # (u, v) = (192, 48) -> image edge coordinates (480, 120) -> pixel-centre convention (479.5, 119.5).
    np.testing.assert_allclose(found[0].keypoints, np.tile([479.5, 119.5], (17, 1)), atol=1e-4)
    np.testing.assert_allclose(found[0].scores, 0.7, atol=1e-6)
    np.testing.assert_allclose(found[0].box, [319.5, -0.5, 639.5, 479.5], atol=1e-4)  # whole right half
    np.testing.assert_allclose(found[1].keypoints, np.tile([159.5, 239.5], (17, 1)), atol=1e-4)
    # box (ymin, xmin, ymax, xmax) = (0.1, 0.2, 0.6, 0.4) -> u 128..256, v 48..288 (edges), minus 0.5.
    np.testing.assert_allclose(found[1].box, [127.5, 47.5, 255.5, 287.5], atol=1e-4)


def test_multipose_on_a_fixed_square_model_undoes_the_padding(tmp_path, people):
    estimator = load_pose_estimator(build_multipose_model(tmp_path / "m.onnx", people, input_hw=(256, 256)))
    assert estimator.input_size == (256, 256)
    found = estimator(np.zeros((480, 640, 3), np.uint8))
    # 640x480 in 256x256: scale 0.4, 32 px bands above and below. y = 0.25 -> 64 input px -> (64 - 32) / 0.4.
    np.testing.assert_allclose(found[0].keypoints[0], [479.5, 80 - 0.5], atol=1e-4)
    np.testing.assert_allclose(found[0].box, [319.5, -0.5, 639.5, 479.5], atol=1e-4)  # clipped to the image
    with pytest.raises(ValueError, match="fixed input"):
        load_pose_estimator(tmp_path / "m.onnx", input_size=(192, 256))


def test_multipose_score_threshold_is_an_option(tmp_path, people):
    path = build_multipose_model(tmp_path / "m.onnx", people)
    assert len(load_pose_estimator(path, score_threshold=0.05)(np.zeros((48, 64, 3), np.uint8))) == 3
    assert load_pose_estimator(path, score_threshold=0.95)(np.zeros((48, 64, 3), np.uint8)) == []


@pytest.mark.parametrize("size", [None, "paper", 320])
@pytest.mark.parametrize(("u", "v"), [(100, 300), (7, 9), (633, 470), (320, 240)])
def test_multipose_marker_comes_back_on_the_red_dot(tmp_path, size, u, v):
    """The marker model reports person 0 at the brightest red input pixel: pre-processing + inverse map agree."""
    rows = np.zeros((6, 56))
    rows[0] = _person(0.0, 0.0, 0.9, box=(-0.01, -0.01, 0.01, 0.01), box_score=0.9)
    estimator = load_pose_estimator(build_multipose_model(tmp_path / "m.onnx", rows, marker=True), input_size=size)
    (person,) = estimator(_red_dot(u, v))
    in_h, in_w = estimator.input_size_for((480, 640))
    pixel = 640 / in_w  # one model-input pixel in image pixels
    assert np.abs(person.keypoints - [u, v]).max() <= 0.5 * pixel + 0.5


def test_multipose_reads_rgb_not_bgr(tmp_path):
    rows = np.zeros((6, 56))
    rows[0] = _person(0.0, 0.0, 0.9)
    estimator = load_pose_estimator(build_multipose_model(tmp_path / "m.onnx", rows, marker=True))
    (person,) = estimator(_red_dot(400, 300, channel=2))  # a blue dot: no red anywhere
    assert np.abs(person.keypoints[0] - [400, 300]).max() > 100


def test_singlepose_in_boxes_maps_crop_centre_to_box_centre(tmp_path):
    keypoints = np.tile([0.5, 0.5, 0.8], (NUM_KEYPOINTS, 1))
    keypoints[0] = [0.0, 0.5, 0.6]  # nose at the crop's top edge
    estimator = load_pose_estimator(build_singlepose_model(tmp_path / "s.onnx", keypoints))
    assert isinstance(estimator, MoveNetSinglePose) and estimator.input_size == (192, 192)
    boxes = np.array([[100.0, 200.0, 140.0, 300.0], [400.0, 50.0, 600.0, 150.0]])
    found = estimator.estimate_in_boxes(np.zeros((480, 640, 3), np.uint8), boxes)
    assert len(found) == 2
    np.testing.assert_allclose(found[0].keypoints[1], [120.0, 250.0], atol=1e-4)
    np.testing.assert_allclose(found[0].keypoints[0], [120.0, 250.0 - 60.0], atol=1e-4)  # 1.2 x 100 px square
    np.testing.assert_allclose(found[1].keypoints[1], [500.0, 100.0], atol=1e-4)
    np.testing.assert_allclose(found[0].box, boxes[0])
    assert found[0].box_score == pytest.approx((16 * 0.8 + 0.6) / 17)
    assert estimator.estimate_in_boxes(np.zeros((480, 640, 3), np.uint8), np.empty((0, 4))) == []


@pytest.mark.parametrize("dtype", [np.uint8, np.int32])
def test_singlepose_marker_in_a_box_comes_back_on_the_dot(tmp_path, dtype):
    estimator = load_pose_estimator(build_singlepose_model(tmp_path / "s.onnx", dtype=dtype, marker=True))
    image = _red_dot(210, 330)
    (found,) = estimator.estimate_in_boxes(image, [[150, 200, 260, 460]])
    pixel = 1.2 * 260 / 192
    assert np.abs(found.keypoints - [210, 330]).max() <= 0.5 * pixel + 0.5


def test_singlepose_crop_hides_neighbours_outside_the_box(tmp_path):
    estimator = load_pose_estimator(build_singlepose_model(tmp_path / "s.onnx", marker=True))
    box = [300, 100, 340, 400]  # tall and narrow: the square crop spans 300 - 180 .. 340 + 180 px in u
    near_dot = _red_dot(380, 250)  # inside the square crop, but 40 px beside the box (margin: 4 px)
    (found,) = estimator.estimate_in_boxes(near_dot, [box])
    assert np.abs(found.keypoints[0] - [380, 250]).max() > 50
    no_mask = MoveNetSinglePose(estimator.model, crop_margin=10.0)
    (found,) = no_mask.estimate_in_boxes(near_dot, [box])
    assert np.abs(found.keypoints[0] - [380, 250]).max() < 3


def test_singlepose_whole_image_mode_thresholds_the_mean_keypoint_score(tmp_path):
    keypoints = np.tile([0.5, 0.5, 0.3], (NUM_KEYPOINTS, 1))
    keypoints[5] = [0.25, 0.25, 0.1]
    estimator = load_pose_estimator(build_singlepose_model(tmp_path / "s.onnx", keypoints))
    (found,) = estimator(np.zeros((480, 640, 3), np.uint8))
    # 640x480 in 192x192: scale 0.3, 24 px bands above and below; (0.5, 0.5) -> image centre.
    np.testing.assert_allclose(found.keypoints[0], [319.5, 239.5], atol=1e-4)
    np.testing.assert_allclose(found.box, [319.5, 239.5, 319.5, 239.5], atol=1e-4)  # the confident keypoints
    assert estimator(np.zeros((480, 640, 3), np.uint8)) and found.box_score == pytest.approx((16 * 0.3 + 0.1) / 17)
    assert load_pose_estimator(tmp_path / "s.onnx", score_threshold=0.5)(np.zeros((480, 640, 3), np.uint8)) == []


def test_singlepose_decode_box_spans_the_confident_keypoints_and_scores_their_exact_mean(tmp_path):
    estimator = load_pose_estimator(build_singlepose_model(tmp_path / "s.onnx"))
    letterbox = Letterbox.fit((480, 640), (192, 192))
    rng = np.random.default_rng(3)
    for _ in range(200):
        output = rng.uniform(-0.2, 1.2, (1, 1, NUM_KEYPOINTS, 3)).astype(np.float32)
        found = estimator.decode(output, letterbox, (480, 640))
        scores = output.reshape(NUM_KEYPOINTS, 3)[:, 2]
        confident = found.keypoints[scores >= estimator.score_threshold]
        pts = confident if len(confident) else found.keypoints
        box = np.concatenate([pts.min(axis=0), pts.max(axis=0)])
        np.testing.assert_array_equal(found.box, np.clip(box, -0.5, [639.5, 479.5, 639.5, 479.5]))
        assert found.box_score == float(scores.mean())  # bit for bit


@pytest.mark.parametrize(
    ("image", "message"),
    [
        (np.zeros((480, 640, 3), np.float32), "uint8"),
        (np.zeros((480, 640), np.uint8), r"\(H, W, 3\)"),
        (np.zeros((0, 640, 3), np.uint8), "empty"),
        ([[0, 0, 0]], "numpy array"),
    ],
)
def test_bad_images_get_clear_errors(tmp_path, image, message):
    estimator = load_pose_estimator(build_multipose_model(tmp_path / "m.onnx"))
    with pytest.raises((ValueError, TypeError), match=message):
        estimator(image)


@pytest.mark.parametrize(
    ("boxes", "message"),
    [([[0, 0, 10]], r"\(N, 4\)"), ([[0, 0, np.nan, 10]], "NaN"), ([[10, 0, 5, 10]], "u_max > u_min")],
)
def test_bad_boxes_get_clear_errors(tmp_path, boxes, message):
    estimator = load_pose_estimator(build_singlepose_model(tmp_path / "s.onnx"))
    with pytest.raises(ValueError, match=message):
        estimator.estimate_in_boxes(np.zeros((48, 64, 3), np.uint8), boxes)
