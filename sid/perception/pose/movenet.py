"""Google MoveNet through onnxruntime: MultiPose (up to 6 people per image) and SinglePose (one person per crop).

Both take RGB 0-255 in NHWC layout and answer (y, x, score) per keypoint, normalised to the model input.
Pre-processing follows ``tf.image.resize_with_pad``: keep the aspect ratio, centre, pad with black.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from sid.perception.keypoints import NUM_KEYPOINTS, PoseDetection
from sid.perception.pose.base import Letterbox, check_boxes, check_color_image, clip_boxes
from sid.perception.pose.contracts import MOVENET_MULTIPOSE, MOVENET_SINGLEPOSE, fixed_hw
from sid.perception.pose.session import OnnxModel

PAD_VALUE = 0  # tf.image.resize_with_pad pads with zeros
MULTIPOSE_LONG_SIDE = 256  # default: 256 px on the long side (TF Hub's suggestion), the other side a multiple of 32
PAPER_WIDTH = 128  # the paper authors' choice: 128 px wide, keeping the aspect ratio
MULTIPOSE_DEFAULT_THRESHOLD = 0.2
SINGLEPOSE_DEFAULT_THRESHOLD = 0.2
# Crops for SinglePose: a square 1.2 x the box's longer side, blacked out beyond 10 % of the box's size around it.
# Without the mask a tall person's square crop shows the neighbours and MoveNet may take their shoulders (measured
# choice: docs/parameters.md).
CROP_EXPAND = 1.2
CROP_MARGIN = 0.1

MultiPoseSize = int | tuple[int, int] | str


def _ceil32(x: float) -> int:
    return max(32, 32 * math.ceil(round(x, 6) / 32))


def multipose_input_size(image_hw: Sequence[int], size: MultiPoseSize = MULTIPOSE_LONG_SIDE) -> tuple[int, int]:
    """MultiPose input (height, width) for an image of ``image_hw`` pixels.

    ``size``: an int L scales the image's long side to L and rounds the other side up to a multiple of 32 (default
    256: 640x480 -> 256x192); ``"paper"`` scales the width to 128 and pads the height up to a multiple of 32, as
    the paper's authors did (640x480 -> 128x96); a (height, width) pair is used as given (multiples of 32).
    """
    h, w = (int(x) for x in image_hw)
    if size == "paper":
        return _ceil32(h * PAPER_WIDTH / w), PAPER_WIDTH
    if isinstance(size, str):
        raise ValueError(f"movenet: input size must be an int, (height, width) or 'paper', got {size!r}")
    if isinstance(size, int):
        if size < 32 or size % 32:
            raise ValueError(f"movenet: MultiPose long side must be a positive multiple of 32, got {size}")
        scale = size / max(h, w)
        return _ceil32(h * scale), _ceil32(w * scale)
    in_h, in_w = (int(x) for x in size)
    if min(in_h, in_w) < 32 or in_h % 32 or in_w % 32:
        raise ValueError(f"movenet: MultiPose input height and width must be multiples of 32, got {in_h}x{in_w}")
    return in_h, in_w


def _keep_only_box(image: np.ndarray, letterbox: Letterbox, box: Sequence[float], margin: float) -> np.ndarray:
    """Set to the pad value every model-input pixel outside ``box`` grown by ``margin`` x its size on each side."""
    u0, v0, u1, v1 = np.asarray(box, dtype=float)
    grow = margin * np.array([u1 - u0, v1 - v0])
    (c0, r0), (c1, r1) = letterbox.to_input(np.array([[u0, v0] - grow, [u1, v1] + grow]))
    in_h, in_w = image.shape[:2]
    c0, r0 = (int(np.clip(np.ceil(x), 0, n)) for x, n in ((c0, in_w), (r0, in_h)))
    c1, r1 = (int(np.clip(np.floor(x) + 1, 0, n)) for x, n in ((c1, in_w), (r1, in_h)))
    out = np.full_like(image, PAD_VALUE)
    out[r0:r1, c0:c1] = image[r0:r1, c0:c1]
    return out


def _keypoints_yx(yx_score: np.ndarray, letterbox: Letterbox) -> tuple[np.ndarray, np.ndarray]:
    """(..., 17, 3) normalised (y, x, score) -> keypoints (..., 17, 2) as image (u, v), scores (..., 17)."""
    return letterbox.normalised_to_image(yx_score[..., 1::-1]), yx_score[..., 2]


class MoveNetMultiPose:
    """MoveNet MultiPose: up to 6 people per image, each with keypoints and a box.

    ``input_size``: the model's own fixed size if it has one, else chosen per image by ``multipose_input_size``
    from ``size``. ``score_threshold`` applies to the person (box) score.
    """

    contract = MOVENET_MULTIPOSE

    def __init__(
        self, model: OnnxModel, score_threshold: float = MULTIPOSE_DEFAULT_THRESHOLD, size: MultiPoseSize | None = None
    ):
        self.model = model
        self.score_threshold = float(score_threshold)
        self._fixed = fixed_hw(model.signature.inputs[0].shape[1:3])
        requested = tuple(size) if isinstance(size, (list, tuple)) else size
        if self._fixed is not None and requested is not None and requested != self._fixed:
            raise ValueError(f"movenet: this MultiPose model has a fixed input {self._fixed}, cannot use size {size!r}")
        self.size = MULTIPOSE_LONG_SIDE if size is None else size
        if self._fixed is None:
            multipose_input_size((480, 640), self.size)  # validate now rather than on the first frame

    @property
    def input_size(self) -> tuple[int, int] | None:
        """Fixed model input (height, width), or None when it is chosen per image (see ``input_size_for``)."""
        return self._fixed

    def input_size_for(self, image_hw: Sequence[int]) -> tuple[int, int]:
        """Model input (height, width) used for an image of ``image_hw`` pixels."""
        return self._fixed or multipose_input_size(image_hw, self.size)

    def preprocess(self, color_rgb: np.ndarray) -> tuple[np.ndarray, Letterbox]:
        """RGB uint8 image -> int32 [1, H, W, 3] input tensor and the letterbox that made it."""
        color_rgb = check_color_image(color_rgb)
        letterbox = Letterbox.fit(color_rgb.shape[:2], self.input_size_for(color_rgb.shape[:2]))
        return letterbox.warp(color_rgb, PAD_VALUE)[None].astype(np.int32), letterbox

    def infer(self, tensor: np.ndarray) -> np.ndarray:
        return self.model.run(tensor)

    def decode(self, output: np.ndarray, letterbox: Letterbox, image_hw: Sequence[int]) -> list[PoseDetection]:
        """[1, 6, 56] model output -> people above the score threshold, best first, in image pixels."""
        rows = output.reshape(-1, 56)
        rows = rows[rows[:, 55] >= self.score_threshold]
        rows = rows[np.argsort(-rows[:, 55], kind="stable")]
        keypoints, scores = _keypoints_yx(rows[:, :51].reshape(-1, NUM_KEYPOINTS, 3), letterbox)
        # Box (ymin, xmin, ymax, xmax) normalised -> two corners (x, y) -> image pixels.
        corners = letterbox.normalised_to_image(rows[:, [52, 51, 54, 53]].reshape(-1, 2, 2)).reshape(-1, 4)
        boxes = clip_boxes(corners, image_hw)
        return [PoseDetection(k, s, b, r) for k, s, b, r in zip(keypoints, scores, boxes, rows[:, 55], strict=True)]

    def __call__(self, color_rgb: np.ndarray) -> list[PoseDetection]:
        tensor, letterbox = self.preprocess(color_rgb)
        return self.decode(self.infer(tensor), letterbox, color_rgb.shape[:2])


class MoveNetSinglePose:
    """MoveNet SinglePose: one person per image or per crop.

    ``__call__`` letterboxes the whole image (good when one person fills much of it); ``estimate_in_boxes`` runs
    once per person box (e.g. from a detector), on a square crop ``crop_expand`` times the box's longer side in
    which everything farther than ``crop_margin`` x the box's size from the box is blacked out (neighbours).
    ``score_threshold`` applies to the mean keypoint score, MoveNet's own "is there a person" measure.
    """

    contract = MOVENET_SINGLEPOSE

    def __init__(
        self,
        model: OnnxModel,
        score_threshold: float = SINGLEPOSE_DEFAULT_THRESHOLD,
        crop_expand: float = CROP_EXPAND,
        crop_margin: float = CROP_MARGIN,
        size: int | None = None,
    ):
        self.model = model
        self.score_threshold = float(score_threshold)
        self.crop_expand = float(crop_expand)
        self.crop_margin = float(crop_margin)
        if self.crop_margin < 0:
            raise ValueError(f"movenet: crop_margin must be >= 0, got {crop_margin}")
        spec = model.signature.inputs[0]
        fixed = fixed_hw(spec.shape[1:3])
        if fixed is not None:
            if size is not None and (size, size) != fixed:
                raise ValueError(f"movenet: this SinglePose model has a fixed input {fixed}, cannot use {size}")
            self._size = fixed
        else:
            side = 192 if size is None else int(size)
            if side < 32:
                raise ValueError(f"movenet: SinglePose input size must be at least 32, got {side}")
            self._size = (side, side)
        self._dtype = spec.dtype

    @property
    def input_size(self) -> tuple[int, int]:
        return self._size

    def preprocess(self, color_rgb: np.ndarray, box: Sequence[float] | None = None) -> tuple[np.ndarray, Letterbox]:
        """Whole image (``box`` None) or a square crop around ``box`` -> [1, H, W, 3] input tensor and its map."""
        color_rgb = check_color_image(color_rgb)
        if box is None:
            letterbox = Letterbox.fit(color_rgb.shape[:2], self._size)
            image = letterbox.warp(color_rgb, PAD_VALUE)
        else:
            letterbox = Letterbox.crop(box, self._size, self.crop_expand)
            image = _keep_only_box(letterbox.warp(color_rgb, PAD_VALUE), letterbox, box, self.crop_margin)
        return image[None].astype(self._dtype, copy=False), letterbox

    def infer(self, tensor: np.ndarray) -> np.ndarray:
        return self.model.run(tensor)

    def decode(self, output: np.ndarray, letterbox: Letterbox, image_hw: Sequence[int]) -> PoseDetection:
        """[1, 1, 17, 3] output -> one detection; its box spans the keypoints scoring at least the threshold
        (all keypoints if none does), its box_score is the mean keypoint score."""
        keypoints, scores = _keypoints_yx(output.reshape(NUM_KEYPOINTS, 3), letterbox)
        confident = scores >= self.score_threshold
        pts = keypoints[confident] if confident.any() else keypoints
        box = clip_boxes(np.concatenate([pts.min(axis=0), pts.max(axis=0)])[None], image_hw)[0]
        return PoseDetection(keypoints, scores, box, float(scores.mean()))

    def __call__(self, color_rgb: np.ndarray) -> list[PoseDetection]:
        """The one person MoveNet sees in the whole image, or [] when its mean keypoint score is too low."""
        tensor, letterbox = self.preprocess(color_rgb)
        detection = self.decode(self.infer(tensor), letterbox, color_rgb.shape[:2])
        return [detection] if detection.box_score >= self.score_threshold else []

    def estimate_in_boxes(
        self, color_rgb: np.ndarray, boxes: np.ndarray | Sequence[Sequence[float]]
    ) -> list[PoseDetection]:
        """One detection per box (N, 4) as (u_min, v_min, u_max, v_max) pixels, in the same order, unfiltered.

        Each detection keeps its input box; box_score is the mean keypoint score (compare it with
        ``score_threshold`` to drop crops where MoveNet found nobody).
        """
        color_rgb = check_color_image(color_rgb)
        detections = []
        for box in check_boxes(boxes):
            tensor, letterbox = self.preprocess(color_rgb, box)
            found = self.decode(self.infer(tensor), letterbox, color_rgb.shape[:2])
            detections.append(PoseDetection(found.keypoints, found.scores, box, found.box_score))
        return detections
