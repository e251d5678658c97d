"""Google MoveNet through onnxruntime: MultiPose (up to 6 people per image) and SinglePose (one person per crop).

Both take RGB 0-255 in NHWC layout and answer (y, x, score) per keypoint, normalised to the model input.
Pre-processing follows ``tf.image.resize_with_pad``: keep the aspect ratio, centre, pad with black.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from sid.errors import InputError
from sid.perception.keypoints import NUM_KEYPOINTS, PoseDetection
from sid.perception.pose.base import (
    Letterbox,
    check_boxes,
    check_color_image,
    clip_corners,
    fit_letterbox,
    most_detections,
)
from sid.perception.pose.contracts import MOVENET_MULTIPOSE, MOVENET_SINGLEPOSE, fixed_hw
from sid.perception.pose.session import OnnxModel

__all__ = [
    "CROP_EXPAND",
    "CROP_MARGIN",
    "MULTIPOSE_DEFAULT_THRESHOLD",
    "MULTIPOSE_LONG_SIDE",
    "MoveNetMultiPose",
    "MoveNetSinglePose",
    "MultiPoseSize",
    "PAD_VALUE",
    "PAPER_WIDTH",
    "SINGLEPOSE_DEFAULT_THRESHOLD",
    "multipose_input_size",
]

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
        raise InputError(f"movenet: input size must be an int, (height, width) or 'paper', got {size!r}")
    if isinstance(size, int):
        if size < 32 or size % 32:
            raise InputError(f"movenet: MultiPose long side must be a positive multiple of 32, got {size}")
        scale = size / max(h, w)
        return _ceil32(h * scale), _ceil32(w * scale)
    in_h, in_w = (int(x) for x in size)
    if min(in_h, in_w) < 32 or in_h % 32 or in_w % 32:
        raise InputError(f"movenet: MultiPose input height and width must be multiples of 32, got {in_h}x{in_w}")
    return in_h, in_w


def _keep_only_box(image: np.ndarray, letterbox: Letterbox, box: Sequence[float], margin: float) -> np.ndarray:
    """Set to the pad value, in place, every model-input pixel outside ``box`` grown by ``margin`` x its size on
    each side; returns ``image``."""
    u0, v0, u1, v1 = (float(x) for x in box)
    grow_u, grow_v = margin * (u1 - u0), margin * (v1 - v0)
    corners = np.array([[u0 - grow_u, v0 - grow_v], [u1 + grow_u, v1 + grow_v]])
    (c0, r0), (c1, r1) = letterbox.to_input(corners).tolist()
    in_h, in_w = image.shape[:2]
    c0, r0 = (min(max(math.ceil(x), 0), n) for x, n in ((c0, in_w), (r0, in_h)))
    c1, r1 = (min(max(math.floor(x) + 1, 0), n) for x, n in ((c1, in_w), (r1, in_h)))
    image[:r0] = PAD_VALUE
    image[r1:] = PAD_VALUE
    image[r0:r1, :c0] = PAD_VALUE
    image[r0:r1, c1:] = PAD_VALUE
    return image


def _corners_yx(rows: np.ndarray) -> np.ndarray:
    """MoveNet's box (ymin, xmin, ymax, xmax) per row (..., 4) -> its two corners (..., 2, 2) as (x, y)."""
    return rows.reshape(*rows.shape[:-1], 2, 2)[..., ::-1]


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
            raise InputError(f"movenet: this MultiPose model has a fixed input {self._fixed}, cannot use size {size!r}")
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
        letterbox = fit_letterbox(color_rgb.shape[:2], self.input_size_for(color_rgb.shape[:2]))
        return letterbox.warp(color_rgb, PAD_VALUE)[None].astype(np.int32), letterbox

    def infer(self, tensor: np.ndarray) -> np.ndarray:
        return self.model.run(tensor)

    def decode(self, output: np.ndarray, letterbox: Letterbox, image_hw: Sequence[int]) -> list[PoseDetection]:
        """[1, 6, 56] model output -> people above the score threshold, best first, in image pixels."""
        rows = output.reshape(-1, 56)
        rows = rows[rows[:, 55] >= self.score_threshold]
        rows = rows[np.argsort(-rows[:, 55], kind="stable")]
        rows = rows[: most_detections(len(rows))]
        # Each person's 17 keypoints and two box corners go through one map to image pixels, all people at once.
        points = np.empty((len(rows), NUM_KEYPOINTS + 2, 2))
        points[:, :NUM_KEYPOINTS] = rows[:, :51].reshape(-1, NUM_KEYPOINTS, 3)[..., 1::-1]
        points[:, NUM_KEYPOINTS:] = _corners_yx(rows[:, 51:55])
        letterbox.normalised_to_image_in_place(points)
        clip_corners(points[:, NUM_KEYPOINTS:], image_hw)
        scores = rows[:, 2:51:3].astype(float)
        return [
            PoseDetection(p[:NUM_KEYPOINTS], s, p[NUM_KEYPOINTS:].reshape(4), r)
            for p, s, r in zip(points, scores, rows[:, 55].tolist(), strict=True)
        ]

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
            raise InputError(f"movenet: crop_margin must be >= 0, got {crop_margin}")
        spec = model.signature.inputs[0]
        fixed = fixed_hw(spec.shape[1:3])
        if fixed is not None:
            if size is not None and (size, size) != fixed:
                raise InputError(f"movenet: this SinglePose model has a fixed input {fixed}, cannot use {size}")
            self._size = fixed
        else:
            side = 192 if size is None else int(size)
            if side < 32:
                raise InputError(f"movenet: SinglePose input size must be at least 32, got {side}")
            self._size = (side, side)
        self._dtype = spec.dtype

    @property
    def input_size(self) -> tuple[int, int]:
        return self._size

    def preprocess(self, color_rgb: np.ndarray, box: Sequence[float] | None = None) -> tuple[np.ndarray, Letterbox]:
        """Whole image (``box`` None) or a square crop around ``box`` -> [1, H, W, 3] input tensor and its map."""
        color_rgb = check_color_image(color_rgb)
        if box is None:
            letterbox = fit_letterbox(color_rgb.shape[:2], self._size)
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
        yx_score = output.reshape(NUM_KEYPOINTS, 3)
        keypoints, scores = letterbox.normalised_to_image(yx_score[:, 1::-1]), yx_score[:, 2]
        pts = keypoints[scores >= self.score_threshold]
        if len(pts) == 0:
            pts = keypoints
        box = np.empty(4)
        np.minimum.reduce(pts, axis=0, out=box[:2])  # ufunc reductions skip the Python wrappers of min and max
        np.maximum.reduce(pts, axis=0, out=box[2:])
        clip_corners(box.reshape(2, 2), image_hw)
        # The float32 sum / 17 equals scores.mean() bit for bit (correctly rounded either way), without np.mean's
        # Python-level wrapper.
        return PoseDetection(keypoints, scores, box, float(scores.sum() / NUM_KEYPOINTS))

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
