"""Ultralytics YOLO-pose exports through onnxruntime: letterbox, decode the [1, 56, N] candidates, NMS.

Pre-processing follows Ultralytics' ``LetterBox``: keep the aspect ratio, centre, pad with grey 114, RGB scaled to
0..1. Candidates are in input pixels (``yolo export format=onnx``) or normalised to the input (TFLite-derived
exports such as the reference 256 px model); which one is found once, on a blank image, when the model is loaded.

NMS is OpenCV's ``cv2.dnn.NMSBoxes`` (greedy, by score, IoU on (x, y, w, h) boxes), the same algorithm as the
torchvision NMS Ultralytics uses; it keeps the same boxes as a numpy greedy NMS, faster (docs/parameters.md), so
the library call is both simpler and faster than writing our own.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from sid.errors import InputError
from sid.perception.keypoints import NUM_KEYPOINTS, PoseDetection
from sid.perception.pose.base import Letterbox, check_color_image, clip_corners, fit_letterbox, most_detections
from sid.perception.pose.contracts import YOLO_POSE, PoseModelError, fixed_hw, yolo_layout
from sid.perception.pose.session import OnnxModel

__all__ = ["DEFAULT_IOU", "DEFAULT_SIZE", "DEFAULT_THRESHOLD", "NORMALISED_LIMIT", "PAD_VALUE", "YoloPose"]

PAD_VALUE = 114  # Ultralytics LetterBox fill
DEFAULT_THRESHOLD = 0.25  # Ultralytics' default confidence for predict
DEFAULT_IOU = 0.7  # Ultralytics' default NMS IoU for predict
DEFAULT_SIZE = 640  # Ultralytics' default export size, for models with dynamic height and width
NORMALISED_LIMIT = 2.0  # pixel exports put candidates all over the input; normalised ones stay within ~[0, 1]


class YoloPose:
    """YOLO-pose: any number of people per image; boxes + 17 keypoints per candidate, overlapping ones merged."""

    contract = YOLO_POSE

    def __init__(
        self,
        model: OnnxModel,
        score_threshold: float = DEFAULT_THRESHOLD,
        iou_threshold: float = DEFAULT_IOU,
        size: int | tuple[int, int] | None = None,
        normalised: bool | None = None,
    ):
        self.model = model
        self.score_threshold = float(score_threshold)
        self.iou_threshold = float(iou_threshold)
        if not 0.0 < self.iou_threshold <= 1.0:
            raise InputError(f"yolo: iou_threshold must be in (0, 1], got {iou_threshold}")
        spec = model.signature.inputs[0]
        self.layout = yolo_layout(spec)
        fixed = fixed_hw(spec.shape[2:4] if self.layout == "nchw" else spec.shape[1:3])
        if fixed is not None:
            if size is not None and tuple(np.broadcast_to(size, 2)) != fixed:
                raise InputError(f"yolo: this model has a fixed input {fixed}, cannot use size {size!r}")
            self._size = fixed
        else:
            h, w = (int(x) for x in np.broadcast_to(DEFAULT_SIZE if size is None else size, 2))
            if min(h, w) < 32 or h % 32 or w % 32:
                raise InputError(f"yolo: input height and width must be multiples of 32, got {h}x{w}")
            self._size = (h, w)
        self._dtype = spec.dtype
        self._pixel_unit = 1.0 / np.array(self._size[::-1], dtype=float)  # input px -> [0, 1], for pixel exports
        probed = self._outputs_normalised()  # also checks the output's real shape, so it runs either way
        self.normalised = probed if normalised is None else bool(normalised)

    @property
    def input_size(self) -> tuple[int, int]:
        return self._size

    def _outputs_normalised(self) -> bool:
        """Run once on a grey image: are candidate centres normalised to the input (all within ~[0, 1])?

        Also checks that the output really is [1, 56, N] (a declared shape may be dynamic), and warms the session
        up, so the first real frame is not slowed by one-off allocations.
        """
        h, w = self._size
        tensor, _ = self.preprocess(np.full((h, w, 3), PAD_VALUE, np.uint8))
        output = self.infer(tensor)
        if output.ndim != 3 or output.shape[:2] != (1, 56):
            raise PoseModelError(
                f"yolo: {self.model.path}: the model answers an output of shape {list(output.shape)} for a "
                f"{h} x {w} input; a YOLO pose export answers [1, 56, N], one column of 56 values per candidate"
            )
        if output.shape[2] == 0:
            raise PoseModelError(
                f"yolo: {self.model.path}: the model answers no candidates (output [1, 56, 0]); a YOLO pose export "
                "answers one per anchor, e.g. 8400 at 640 x 640"
            )
        return bool(np.nanmax(np.abs(output[0, :2])) <= NORMALISED_LIMIT)

    def preprocess(self, color_rgb: np.ndarray) -> tuple[np.ndarray, Letterbox]:
        """RGB uint8 image -> float [1, H, W, 3] or [1, 3, H, W] input in 0..1, and the letterbox that made it."""
        color_rgb = check_color_image(color_rgb)
        letterbox = fit_letterbox(color_rgb.shape[:2], self._size)
        image = letterbox.warp(color_rgb, PAD_VALUE)
        if self.layout == "nchw":
            image = image.transpose(2, 0, 1)
        tensor = np.multiply(image[None], 1.0 / 255.0, dtype=np.float32)
        return tensor.astype(self._dtype, copy=False), letterbox

    def infer(self, tensor: np.ndarray) -> np.ndarray:
        return self.model.run(tensor)

    def decode(self, output: np.ndarray, letterbox: Letterbox, image_hw: Sequence[int]) -> list[PoseDetection]:
        """[1, 56, N] candidates -> people above the score threshold after NMS, best first, in image pixels."""
        rows = output.reshape(56, -1)
        above = (rows[4] >= self.score_threshold).nonzero()[0]
        if len(above) == 0:
            return []
        rects = rows[:5].take(above, axis=1)  # the few candidates above the threshold: centre x, y, w, h, score
        rects[:2] -= rects[2:4] / 2  # centre -> top-left corner (edge coordinates), in float32 like the model
        keep = cv2.dnn.NMSBoxes(rects[:4].T.tolist(), rects[4].tolist(), self.score_threshold, self.iou_threshold)
        best = np.asarray(keep, dtype=np.intp).reshape(-1)  # best first
        kept = rows.take(above[best[: most_detections(len(best))]], axis=1).T  # (people, 56)
        return self._detections(kept, letterbox, image_hw)

    def _detections(self, kept: np.ndarray, letterbox: Letterbox, image_hw: Sequence[int]) -> list[PoseDetection]:
        """Kept candidates (people, 56) -> detections in image pixels, boxes clipped to the image."""
        # Each person's 17 keypoints and two box corners go through one map to image pixels, all people at once.
        points = np.empty((len(kept), NUM_KEYPOINTS + 2, 2))
        points[:, :NUM_KEYPOINTS] = kept[:, 5:].reshape(-1, NUM_KEYPOINTS, 3)[..., :2]
        centre, half = kept[:, 0:2], kept[:, 2:4] / 2  # float32, as the model gives them
        points[:, NUM_KEYPOINTS] = centre - half
        points[:, NUM_KEYPOINTS + 1] = centre + half
        if not self.normalised:
            points *= self._pixel_unit
        letterbox.normalised_to_image_in_place(points)
        clip_corners(points[:, NUM_KEYPOINTS:], image_hw)
        scores = kept[:, 7::3].astype(float)
        return [
            PoseDetection(p[:NUM_KEYPOINTS], s, p[NUM_KEYPOINTS:].reshape(4), c)
            for p, s, c in zip(points, scores, kept[:, 4].tolist(), strict=True)
        ]

    def __call__(self, color_rgb: np.ndarray) -> list[PoseDetection]:
        tensor, letterbox = self.preprocess(color_rgb)
        return self.decode(self.infer(tensor), letterbox, color_rgb.shape[:2])
