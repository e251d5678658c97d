"""Camera calibration records and pinhole (de)projection.

Frames: camera optical frame, x right, y down, z forward (metres). Pixel coordinates (u, v) follow
librealsense: (0, 0) is the centre of the top-left pixel, u grows to the right, v downwards.

Distortion: the D435i colour and depth streams report (near-)zero distortion ("Brown-Conrady" with zero
coefficients, or "inverse Brown-Conrady" on colour); the coefficients are kept in the record but every
function here treats the camera as an ideal pinhole. Undistort images first if your camera has real distortion:
every reader of a calibration (JSON, RealSense, ROS CameraInfo) says so with ``warn_distortion``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sid.checks import check_limit, check_number, check_numbers
from sid.documents import InputWarning, is_number, load_document, summary
from sid.errors import InputError

__all__ = [
    "Calibration",
    "Extrinsics",
    "INTRINSICS_FIELDS",
    "Intrinsics",
    "MAX_BASELINE",
    "MAX_FOCAL_PER_PIXEL",
    "MAX_IMAGE_SIDE",
    "MIN_FOCAL_PER_PIXEL",
    "deproject",
    "pixel_rays",
    "project",
    "warn_distortion",
]

MAX_IMAGE_SIDE = 100_000
"""The largest image width or height a calibration file may give (pixels)."""


MAX_FOCAL_PER_PIXEL = 100.0
"""Largest focal length (pixels) per pixel of image width or height that ``Intrinsics`` accepts: a field of view of
~0.6 degrees; a larger one is a unit mistake (e.g. micrometres), not a camera."""
MAX_BASELINE = 1.0
"""Longest depth-to-colour translation (m) a calibration may have: an RGB-D camera's sensors sit centimetres apart."""
INTRINSICS_FIELDS = ("width", "height", "fx", "fy", "cx", "cy", "ppx", "ppy", "model", "coeffs")
"""The fields ``Intrinsics.from_dict`` reads (``ppx``/``ppy`` for ``cx``/``cy``)."""
MIN_FOCAL_PER_PIXEL = 0.01
"""Smallest focal length (pixels) per pixel of image width or height: a field of view of ~178 degrees, as wide as a
pinhole model goes; below it a viewing ray's slope (pixel offset / focal length) overflows to infinity."""


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics of one stream (pixels)."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    model: str = "none"
    coeffs: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        if self.width <= 0 or self.height <= 0:
            raise InputError(f"intrinsics: image size must be positive, got {self.width}x{self.height}")
        detail = f"{self.width} x {self.height} = "  # every frame of this camera is decoded at this size
        check_limit("intrinsics: image", self.width * self.height, "image_pixels", "pixels", detail)
        check_numbers("intrinsics", self, ("fx", "fy", "cx", "cy"), unit="pixels")
        if self.fx <= 0 or self.fy <= 0:
            raise InputError(f"intrinsics: focal lengths must be positive, got fx={self.fx}, fy={self.fy}")
        # A real camera's optical axis meets its own image, and its field of view spans half a degree to 178 degrees.
        check_number("intrinsics", "cx", self.cx, low=0, high=self.width, unit="pixels")
        check_number("intrinsics", "cy", self.cy, low=0, high=self.height, unit="pixels")
        for name, side in (("fx", self.width), ("fy", self.height)):
            low, high = MIN_FOCAL_PER_PIXEL * side, MAX_FOCAL_PER_PIXEL * side
            check_number("intrinsics", name, getattr(self, name), low=low, high=high, unit="pixels")

    @property
    def K(self) -> np.ndarray:  # noqa: N802 - K is the standard name of the camera matrix
        """3x3 camera matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def scaled(self, width: int, height: int) -> Intrinsics:
        """The same camera at another resolution (for resized images)."""
        sx, sy = width / self.width, height / self.height
        return Intrinsics(
            width,
            height,
            self.fx * sx,
            self.fy * sy,
            (self.cx + 0.5) * sx - 0.5,
            (self.cy + 0.5) * sy - 0.5,
            self.model,
            self.coeffs,
        )

    @classmethod
    def from_rs(cls, intr: Any) -> Intrinsics:
        """From a ``pyrealsense2.intrinsics`` object (an InputWarning when its distortion is not zero)."""
        intrinsics = cls(
            int(intr.width),
            int(intr.height),
            float(intr.fx),
            float(intr.fy),
            float(intr.ppx),
            float(intr.ppy),
            str(intr.model).split(".")[-1],
            tuple(float(c) for c in intr.coeffs),
        )
        warn_distortion(intrinsics, "realsense intrinsics")
        return intrinsics

    @classmethod
    def from_dict(cls, data: Any, where: str = "intrinsics") -> Intrinsics:
        """From ``{"width", "height", "fx", "fy", "cx", "cy"}`` (``ppx``/``ppy`` accepted for cx/cy).

        A missing or mistyped field is a ValueError naming ``where`` (e.g. ``color``), the field and its value.
        """
        if not isinstance(data, dict):
            raise InputError(f"{where}: expected an object with width, height, fx, fy, cx, cy, got {summary(data)}")
        width, height = (_pixel_count(data, key, where) for key in ("width", "height"))
        fx, fy = (_number(data, key, where, low=0, low_open=True, unit="pixels") for key in ("fx", "fy"))
        cx = _number(data, "cx" if "cx" in data or "ppx" not in data else "ppx", where, unit="pixels")
        cy = _number(data, "cy" if "cy" in data or "ppy" not in data else "ppy", where, unit="pixels")
        model = data.get("model", "none")
        if not isinstance(model, str):
            raise InputError(f"{where}: model must be a distortion model name, got {summary(model)}")
        coeffs = data.get("coeffs", [0.0] * 5)
        if not (isinstance(coeffs, list) and all(is_number(c) for c in coeffs)):
            raise InputError(f"{where}: coeffs must be a list of numbers, got {summary(coeffs)}")
        return cls(width, height, fx, fy, cx, cy, model, tuple(float(c) for c in coeffs))

    def to_dict(self) -> dict[str, Any]:
        return {
            "width": self.width,
            "height": self.height,
            "fx": self.fx,
            "fy": self.fy,
            "cx": self.cx,
            "cy": self.cy,
            "model": self.model,
            "coeffs": list(self.coeffs),
        }


@dataclass(frozen=True)
class Extrinsics:
    """Rigid transform from frame A to frame B: ``p_B = rotation @ p_A + translation`` (metres)."""

    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    translation: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        rotation = np.asarray(self.rotation, dtype=float).reshape(3, 3)
        translation = np.asarray(self.translation, dtype=float).reshape(3)
        if not (np.all(np.isfinite(rotation)) and np.all(np.isfinite(translation))):
            raise InputError("extrinsics: rotation and translation must be finite")
        if not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-5):
            raise InputError("extrinsics: rotation is not orthonormal")
        if np.linalg.det(rotation) < 0:  # orthonormal, but a reflection: it would mirror the depth points
            raise InputError("extrinsics: rotation has determinant -1, a mirror rather than a rotation")
        object.__setattr__(self, "rotation", rotation)
        object.__setattr__(self, "translation", translation)

    def apply(self, points: np.ndarray) -> np.ndarray:
        """Transform (N, 3) points from frame A to frame B."""
        return points @ self.rotation.T + self.translation

    @classmethod
    def from_rs(cls, extr: Any) -> Extrinsics:
        """From a ``pyrealsense2.extrinsics`` (its rotation is stored column-major)."""
        return cls(np.asarray(extr.rotation, dtype=float).reshape(3, 3).T, np.asarray(extr.translation))

    @classmethod
    def from_dict(cls, data: Any, where: str = "extrinsics") -> Extrinsics:
        """From ``{"rotation": 3x3 row-major nested list, "translation": [x, y, z]}``.

        A missing or mistyped field is a ValueError naming ``where`` (e.g. ``depth_to_color``), the field and its value.
        """
        if not isinstance(data, dict):
            raise InputError(f"{where}: expected an object with rotation and translation, got {summary(data)}")
        rotation = _numbers(data, "rotation", where, 9, "a 3x3 row-major matrix of numbers")
        translation = _numbers(data, "translation", where, 3, "[x, y, z] in metres")
        try:
            return cls(rotation, translation)
        except ValueError as exc:  # e.g. a rotation that is not one
            raise InputError(f"{where}: {str(exc).removeprefix('extrinsics: ')}") from None

    def to_dict(self) -> dict[str, Any]:
        return {"rotation": self.rotation.tolist(), "translation": self.translation.tolist()}


@dataclass(frozen=True)
class Calibration:
    """Everything needed to align depth to colour and lift colour pixels to 3D.

    ``depth`` is None when the depth image is already registered to the colour image; ``depth_to_color`` must
    then be the identity (a ValueError otherwise: its depth intrinsics are missing, e.g. a misspelt section).
    ``depth_to_color`` maps depth-camera points to colour-camera points. ``depth_scale`` is metres per
    depth unit (0.001 for millimetre PNGs and the D435i default).
    """

    color: Intrinsics
    depth: Intrinsics | None = None
    depth_to_color: Extrinsics = field(default_factory=Extrinsics)
    depth_scale: float = 0.001

    def __post_init__(self) -> None:
        extrinsics = self.depth_to_color
        identity = np.array_equal(extrinsics.rotation, np.eye(3)) and not extrinsics.translation.any()
        if self.depth is None and not identity:
            raise InputError(
                "depth_to_color is not the identity but there are no depth intrinsics: without them the depth "
                "image is taken as registered to colour and the transform would be ignored; give the depth section "
                "(or drop depth_to_color if the depth image is registered)"
            )
        baseline = float(np.linalg.norm(extrinsics.translation))
        if baseline > MAX_BASELINE:
            raise InputError(
                f"depth_to_color: translation {baseline:g} m is more than {MAX_BASELINE:g} m; the two sensors of an "
                "RGB-D camera sit centimetres apart (metres expected, not millimetres)"
            )
        check_number("calibration", "depth_scale", self.depth_scale, low=0, low_open=True, high=1, unit="metres")

    @classmethod
    def from_json(cls, path: str | Path) -> Calibration:
        """Read a calibration JSON.

        Accepted forms: ``{"color": {...}, "depth": {...}, "depth_to_color": {...}, "depth_scale": s}`` or a
        flat intrinsics dict (``fx, fy, cx, cy, width, height[, depth_scale]``) for a registered RGB-D pair.
        ``depth_scale_m`` is accepted for ``depth_scale``; a flat dict with ``"depth_aligned_to_color": false`` is
        refused (unregistered depth needs the depth intrinsics and extrinsics). Every error is a ValueError naming
        the file, and the field and its value when one is at fault. Other fields are ignored, but an InputWarning
        names those holding numbers or objects (a misspelt ``depth_scale`` would leave depth ten times off, a
        misspelt ``depth`` section would leave the depth taken as registered), and one names distortion
        coefficients that are not all zero (they are not applied).
        """
        path = Path(path)
        data = load_document(path, "calibration JSON")  # names the file itself
        if not isinstance(data, dict):
            raise InputError(f"calibration {path}: expected a JSON object, got {summary(data)}")
        depth_scale = _depth_scale(data, f"calibration {path}")
        if "color" in data:
            extrinsics = data.get("depth_to_color")
            sections = [
                ("", data, ("color", "depth", "depth_to_color", "depth_scale", "depth_scale_m")),
                ("color: ", data["color"], INTRINSICS_FIELDS),
                ("depth: ", data.get("depth"), INTRINSICS_FIELDS),
                ("depth_to_color: ", extrinsics, ("rotation", "translation")),
            ]
        else:
            flat = (*INTRINSICS_FIELDS, "depth_scale", "depth_scale_m", "depth_aligned_to_color")
            sections = [("", data, flat)]
        for where, section, known in sections:  # before the checks: an unread section may explain an error
            if isinstance(section, dict):
                _warn_unused(f"calibration {path}: {where}", section, known)
        try:
            if "color" in data:
                calibration = cls(
                    Intrinsics.from_dict(data["color"], "color"),
                    Intrinsics.from_dict(data["depth"], "depth") if data.get("depth") is not None else None,
                    Extrinsics.from_dict(extrinsics, "depth_to_color") if extrinsics is not None else Extrinsics(),
                    depth_scale,
                )
            else:
                if data.get("depth_aligned_to_color") is False:
                    raise InputError("depth is not aligned to colour; give color, depth and depth_to_color sections")
                calibration = cls(Intrinsics.from_dict(data), depth_scale=depth_scale)
        except ValueError as exc:
            raise InputError(f"calibration {path}: {exc}") from None
        for name, intrinsics in (("color", calibration.color), ("depth", calibration.depth)):
            if intrinsics is not None:
                warn_distortion(intrinsics, f"calibration {path}: {name}" if "color" in data else f"calibration {path}")
        return calibration

    def to_dict(self) -> dict[str, Any]:
        return {
            "color": self.color.to_dict(),
            "depth": self.depth.to_dict() if self.depth else None,
            "depth_to_color": self.depth_to_color.to_dict(),
            "depth_scale": self.depth_scale,
        }


def _depth_scale(data: dict[str, Any], where: str) -> float:
    """``depth_scale`` (or ``depth_scale_m``), metres per depth unit; 0.001 when absent."""
    key = "depth_scale" if "depth_scale" in data or "depth_scale_m" not in data else "depth_scale_m"
    return _number({key: 0.001} | data, key, where, low=0, low_open=True, high=1, unit="metres per unit")


def _warn_unused(where: str, data: dict[str, Any], known: tuple[str, ...]) -> None:
    """An InputWarning for the fields of a calibration section ``data`` that sid does not read: those not in ``known``
    that hold numbers or objects (a misspelt field or section keeps its default silently otherwise; text, such as
    a note, is let be)."""
    unread = [key for key, value in data.items() if key not in known and (_numeric(value) or isinstance(value, dict))]
    if unread:
        warnings.warn(
            f"{where}fields sid does not read: {summary(unread)} (it reads {', '.join(known)}); a misspelt field "
            "keeps its default",
            InputWarning,
            stacklevel=3,
        )


def warn_distortion(intrinsics: Intrinsics, where: str) -> None:
    """An InputWarning naming ``where`` when ``intrinsics`` has distortion coefficients that are not all zero: every
    function here treats the camera as an ideal pinhole, so they are not applied."""
    if any(c != 0 for c in intrinsics.coeffs):
        coeffs = ", ".join(f"{c:.6g}" for c in intrinsics.coeffs)  # float32 readings (librealsense) shown short
        warnings.warn(
            f"{where}: distortion coefficients [{coeffs}] are not applied: sid treats the camera as an ideal "
            "pinhole; undistort the images first",
            InputWarning,
            stacklevel=2,
        )


def _numeric(value: Any) -> bool:
    """Whether a parsed JSON value is a number, or a non-empty list of numbers or of lists of numbers (a matrix)."""
    rows = value if isinstance(value, list) else [value]
    items = [x for row in rows for x in (row if isinstance(row, list) else [row])]
    return bool(items) and all(is_number(x) for x in items)


def _number(data: dict[str, Any], key: str, where: str, **bounds: Any) -> float:
    """``data[key]`` as a float: ValueError ``"where: key ..."`` when it is missing, not a number or out of bounds
    (``bounds`` as in ``sid.checks.check_number``)."""
    if key not in data:
        raise InputError(f"{where}: missing field {key!r}")
    value = data[key]
    if not is_number(value):
        raise InputError(f"{where}: {key} must be a number, got {summary(value)}")
    check_number(where, key, value, **bounds)
    return float(value)


def _pixel_count(data: dict[str, Any], key: str, where: str) -> int:
    """``data[key]`` as a whole number of pixels in [1, MAX_IMAGE_SIDE] (image width or height)."""
    value = _number(data, key, where, low=1, high=MAX_IMAGE_SIDE, unit="pixels")
    if not value.is_integer():
        raise InputError(f"{where}: {key} must be a whole number of pixels, got {summary(data[key])}")
    return int(value)


def _numbers(data: dict[str, Any], key: str, where: str, count: int, rule: str) -> np.ndarray:
    """``data[key]``, a list of ``count`` numbers or of lists of numbers (rows), flattened."""
    if key not in data:
        raise InputError(f"{where}: missing field {key!r}")
    value = data[key]
    flat = [x for row in value for x in (row if isinstance(row, list) else [row])] if isinstance(value, list) else None
    if flat is None or len(flat) != count or not all(is_number(x) for x in flat):
        raise InputError(f"{where}: {key} must be {rule}, got {summary(value)}")
    return np.array(flat, dtype=float)


def pixel_rays(u: Any, v: Any, intrinsics: Intrinsics) -> tuple[Any, Any]:
    """Pixel columns ``u`` and rows ``v`` -> normalised image coordinates x = (u - cx) / fx, y = (v - cy) / fy.

    The camera-frame viewing ray through pixel (u, v) is K^-1 [u v 1] = (x, y, 1) (optical frame), its point at
    depth z (metres) z * (x, y, 1). ``u`` and ``v`` are numbers or arrays, each mapped on its own (their shapes need
    not match: a row of columns and a column of rows give each pixel's x and y).
    """
    return (u - intrinsics.cx) / intrinsics.fx, (v - intrinsics.cy) / intrinsics.fy


def deproject(pixels: np.ndarray, depth_m: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """Pixels (N, 2) as (u, v) with depths (N,) in metres -> (N, 3) camera-frame points: d * K^-1 [u v 1]."""
    pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
    depth_m = np.asarray(depth_m, dtype=float).reshape(-1)
    x, y = pixel_rays(pixels[:, 0], pixels[:, 1], intrinsics)
    return np.stack([x * depth_m, y * depth_m, depth_m], axis=1)


def project(points: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """Camera-frame points (N, 3) -> pixels (N, 2) as (u, v). Points with z <= 0 give NaN."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    z = points[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(z > 0, points[:, 0] / z * intrinsics.fx + intrinsics.cx, np.nan)
        v = np.where(z > 0, points[:, 1] / z * intrinsics.fy + intrinsics.cy, np.nan)
    return np.stack([u, v], axis=1)
