"""What every pose estimator offers, and the letterbox arithmetic that maps model inputs back to image pixels.

Pixel convention (as in ``sid.perception.camera``): ``(u, v) = (0, 0)`` is the centre of the top-left pixel, u grows to
the right, v downwards, so the image's outer edge runs from -0.5 to ``width - 0.5``. Models report positions in
continuous *edge* coordinates of their input (0 = the left edge of the first pixel; a normalised coordinate ``n`` is ``n
* width``), which is why the maps below carry the half-pixel terms.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import Protocol, runtime_checkable

import cv2
import numpy as np

from sid.checks import LIMITS_ENV, amount, check_number, check_numbers, limits
from sid.documents import InputWarning
from sid.errors import InputError, InputTypeError
from sid.perception.keypoints import PoseDetection

__all__ = [
    "Letterbox",
    "PoseEstimator",
    "check_boxes",
    "check_color_image",
    "validate_color_image",
    "clip_corners",
    "fit_letterbox",
    "most_detections",
]


@runtime_checkable
class PoseEstimator(Protocol):
    """A pose model behind one call: RGB uint8 image in, people with 17 COCO keypoints in image pixels out."""

    contract: str
    """Name of the model contract (``movenet_multipose``, ``movenet_singlepose``, ``yolo_pose``)."""

    @property
    def input_size(self) -> tuple[int, int] | None:
        """Model input (height, width) in pixels, or None when it depends on the image (dynamic MultiPose)."""
        ...

    def __call__(self, color_rgb: np.ndarray) -> list[PoseDetection]: ...


@dataclass(frozen=True)
class Letterbox:
    """Uniform scale plus shift from colour-image pixels to model-input pixels (no rotation, no shear).

    In edge coordinates ``x_input = scale * x_image + pad_x`` (same for y). ``pad_x, pad_y`` place the image's
    top-left corner in the model input (model-input pixels): positive for the padding bands of a letterbox,
    negative when a crop starts inside the image. ``input_size`` is the model input (height, width).
    """

    scale: float
    pad_x: float
    pad_y: float
    input_size: tuple[int, int]

    def __post_init__(self) -> None:
        check_number("letterbox", "scale", self.scale, low=0, low_open=True)
        check_numbers("letterbox", self, ("pad_x", "pad_y"), unit="pixels")
        if min(self.input_size) <= 0:
            raise InputError(f"letterbox: input size must be positive, got {self.input_size}")

    @classmethod
    def fit(cls, image_hw: Sequence[int], input_hw: Sequence[int]) -> Letterbox:
        """Fit a whole image into the input keeping its aspect ratio, centred, with whole-pixel padding bands."""
        (h, w), (in_h, in_w) = _size(image_hw, "image"), _size(input_hw, "input")
        scale = min(in_w / w, in_h / h)
        pad_x = (in_w - round(w * scale)) // 2
        pad_y = (in_h - round(h * scale)) // 2
        return cls(scale, float(pad_x), float(pad_y), (in_h, in_w))

    @classmethod
    def crop(cls, box: Sequence[float], input_hw: Sequence[int], expand: float = 1.2) -> Letterbox:
        """A square crop centred on ``box`` (u_min, v_min, u_max, v_max; pixels), its side ``expand`` times the
        box's longer side, scaled to fill the input. Parts of the crop outside the image are padding."""
        in_h, in_w = _size(input_hw, "input")
        u0, v0, u1, v1 = np.asarray(box, dtype=float).reshape(4).tolist()
        if not all(map(math.isfinite, (u0, v0, u1, v1))) or u1 <= u0 or v1 <= v0:
            raise InputError(f"letterbox: box must be finite with u_max > u_min and v_max > v_min, got {box}")
        if not expand > 0:
            raise InputError(f"letterbox: expand must be positive, got {expand}")
        side = expand * max(u1 - u0, v1 - v0)
        scale = min(in_w, in_h) / side
        # Box centre in edge coordinates is (u + 0.5); it must land on the input's centre.
        centre_x, centre_y = (u0 + u1) / 2 + 0.5, (v0 + v1) / 2 + 0.5
        return cls(scale, in_w / 2 - scale * centre_x, in_h / 2 - scale * centre_y, (in_h, in_w))

    def to_input(self, uv: np.ndarray) -> np.ndarray:
        """Image pixels (..., 2) as (u, v) -> model-input pixels (u, v), both pixel-centre convention."""
        uv = np.asarray(uv, dtype=float)
        return (uv + 0.5) * self.scale + np.array([self.pad_x, self.pad_y]) - 0.5

    def normalised_to_image(self, xy: np.ndarray) -> np.ndarray:
        """Model outputs normalised to the input, (..., 2) as (x, y) in [0, 1] -> image pixels (u, v)."""
        return self.normalised_to_image_in_place(np.array(xy, dtype=float))

    def normalised_to_image_in_place(self, xy: np.ndarray) -> np.ndarray:
        """``normalised_to_image`` of a float64 array (..., 2), overwriting it; returns it.

        The same four operations, without temporaries: a decoder's arrays are small, so the call count is its cost.
        """
        size, pad = self._input_terms
        xy *= size
        xy -= pad
        xy /= self.scale
        xy -= 0.5
        return xy

    @cached_property
    def _input_terms(self) -> tuple[np.ndarray, np.ndarray]:
        """Input (width, height) and (pad_x, pad_y) in model-input pixels, as arrays built once per letterbox."""
        in_h, in_w = self.input_size
        return np.array([in_w, in_h], dtype=float), np.array([self.pad_x, self.pad_y])

    def matrix(self) -> np.ndarray:
        """2x3 affine matrix of ``to_input`` (pixel-centre convention), as ``cv2.warpAffine`` takes it."""
        offset = 0.5 * self.scale - 0.5
        return np.array(
            [[self.scale, 0.0, self.pad_x + offset], [0.0, self.scale, self.pad_y + offset]], dtype=np.float64
        )

    def warp(self, color: np.ndarray, fill: int) -> np.ndarray:
        """Resample ``color`` (H, W, 3) uint8 into the model input (bilinear, ``fill`` grey outside the image).

        One ``cv2.warpAffine`` both resizes and pads, so the pixels follow exactly the map of ``to_input``
        (``cv2.resize`` would round the resized size and scale the two axes slightly differently). When the image
        shrinks to fill whole pixels of the input exactly (640x480 into 256x256: 256x192 at scale 0.4, 32-pixel bands),
        ``cv2.resize`` samples at the same positions; its fixed-point weights round differently, by at most one grey
        level. It resizes straight into the new input array, of which only the bands are filled. It was chosen as
        the faster where it was measured first, is not on every host, and is what the INT8 models were calibrated
        and checked on (docs/benchmarks.md, "Pose models").
        """
        in_h, in_w = self.input_size
        resize = _resize_plan(self, *color.shape[:2])
        if resize is None:
            return cv2.warpAffine(
                color,
                self.matrix(),
                (in_w, in_h),
                flags=cv2.INTER_LINEAR,
                borderMode=cv2.BORDER_CONSTANT,
                borderValue=(fill, fill, fill),
            )
        width, height = resize
        top, left = int(self.pad_y), int(self.pad_x)
        bottom, right = top + height, left + width
        # Cheaper than a resize into its own array and then cv2.copyMakeBorder: one pass, one allocation.
        out = np.empty((in_h, in_w, *color.shape[2:]), np.uint8)
        if top > 0:
            out[:top] = fill
        if bottom < in_h:
            out[bottom:] = fill
        if left > 0:
            out[top:bottom, :left] = fill
        if right < in_w:
            out[top:bottom, right:] = fill
        inner = out[top:bottom, left:right]
        written = cv2.resize(color, (width, height), dst=inner, interpolation=cv2.INTER_LINEAR)
        if written is not inner:  # OpenCV's binding wrote a copy instead (never seen with these strides)
            inner[...] = written
        return out


@lru_cache(maxsize=64)
def _resize_plan(letterbox: Letterbox, h: int, w: int) -> tuple[int, int] | None:
    """The resized (width, height) when an image of ``h`` x ``w`` pixels shrinks onto whole input pixels inside
    the input (``Letterbox.warp`` may then resize and pad), else None (it needs ``cv2.warpAffine``). Cached: the
    same letterbox serves every frame of a camera."""
    in_h, in_w = letterbox.input_size
    scale, pad_x, pad_y = letterbox.scale, letterbox.pad_x, letterbox.pad_y
    width, height = scale * w, scale * h
    # Shrinking only: upscaling samples beyond the edge pixels' centres, where warpAffine blends ``fill`` in.
    exact_fit = all(float(v).is_integer() for v in (width, height, pad_x, pad_y)) and scale <= 1
    inside = min(pad_x, pad_y) >= 0 and pad_x + width <= in_w and pad_y + height <= in_h
    return (int(width), int(height)) if exact_fit and inside else None


@lru_cache(maxsize=64)
def fit_letterbox(image_hw: tuple[int, ...], input_hw: tuple[int, ...]) -> Letterbox:
    """``Letterbox.fit``, built once per (image size, input size) pair: a camera's frames all share one."""
    return Letterbox.fit(image_hw, input_hw)


def most_detections(found: int) -> int:
    """How many of a frame's ``found`` detections (best first) to keep: at most ``Limits.detections``, as
    Ultralytics' ``max_det`` keeps the best 300; an ``InputWarning`` says when some are dropped (a model answering
    thousands of people would make the lifting and grouping stages allocate for each pair)."""
    keep = limits().detections
    if found > keep:
        warnings.warn(
            f"pose: the model found {amount(found)} people in one frame, more than the limit of {keep:,} detections; "
            f"the {keep:,} highest-scoring kept (detections; raise it with {LIMITS_ENV}=detections=N)",
            InputWarning,
            stacklevel=3,
        )
    return min(found, keep)


def check_color_image(color_rgb: np.ndarray, what: str = "pose") -> np.ndarray:
    """Validate a colour image (``validate_color_image``); returns it as a C-contiguous array."""
    validate_color_image(color_rgb, what)
    return np.ascontiguousarray(color_rgb)


def validate_color_image(color_rgb: np.ndarray, what: str = "pose") -> None:
    """Raise unless ``color_rgb`` is a colour image: (H, W, 3) uint8 RGB, non-empty; ``what`` names the caller in the
    message. Nothing is copied."""
    if not isinstance(color_rgb, np.ndarray):
        raise InputTypeError(f"{what}: colour image must be a numpy array, got {type(color_rgb).__name__}")
    if color_rgb.ndim != 3 or color_rgb.shape[2] != 3:
        raise InputError(f"{what}: colour image must have shape (H, W, 3) RGB, got {color_rgb.shape}")
    if color_rgb.shape[0] == 0 or color_rgb.shape[1] == 0:
        raise InputError(f"{what}: colour image is empty, shape {color_rgb.shape}")
    if color_rgb.dtype != np.uint8:
        raise InputError(f"{what}: colour image must be uint8 (0-255), got {color_rgb.dtype}")


def check_boxes(boxes: np.ndarray | Sequence[Sequence[float]]) -> np.ndarray:
    """Validate person boxes: (N, 4) finite (u_min, v_min, u_max, v_max) with positive width and height."""
    boxes = np.asarray(boxes, dtype=float)
    if boxes.size == 0:
        return boxes.reshape(0, 4)
    if boxes.ndim != 2 or boxes.shape[1] != 4:
        raise InputError(f"pose: boxes must have shape (N, 4) as (u_min, v_min, u_max, v_max), got {boxes.shape}")
    if not np.all(np.isfinite(boxes)):
        raise InputError("pose: boxes contain NaN or infinite values")
    if np.any(boxes[:, 2] <= boxes[:, 0]) or np.any(boxes[:, 3] <= boxes[:, 1]):
        raise InputError("pose: every box needs u_max > u_min and v_max > v_min")
    return boxes


def clip_corners(corners: np.ndarray, image_hw: Sequence[int]) -> None:
    """Clip box corners (..., 2) as (u, v), in place, to the image's outer edge: -0.5 .. size - 0.5 (pixel-centre
    convention)."""
    h, w = image_hw
    np.maximum(corners, -0.5, out=corners)  # np.clip's Python wrapper costs more than these two ufunc calls
    np.minimum(corners, (w - 0.5, h - 0.5), out=corners)


def _size(hw: Sequence[int], what: str) -> tuple[int, int]:
    h, w = (int(x) for x in hw)
    if h <= 0 or w <= 0:
        raise InputError(f"letterbox: {what} size must be positive, got {tuple(hw)}")
    return h, w
