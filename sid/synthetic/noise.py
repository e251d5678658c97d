"""D435-like depth noise and 2D keypoint noise.

Depth: Intel's model for the RMS depth error of an active-stereo D400 camera (Intel RealSense white paper
"Tuning depth cameras for best performance", Grunnet-Jepsen et al.) is

    RMS(z) = z^2 * subpixel / (focal_px * baseline)

with the disparity error ``subpixel`` ~0.08 px on well-textured surfaces (0.05-0.1 typical, worse on dark or
shiny ones), the D435's 50 mm baseline and the depth focal length in pixels (~420 px at 848x480). That gives
0.38 % of the distance at 1 m and 0.76 % (15 mm) at 2 m; the D435 datasheet bounds the error at <= 2 % at 2 m.
Errors are Gaussian, optionally spatially correlated (block matching shares pixels between neighbours), then
quantised to the depth unit (1 mm). Holes: a random fraction of pixels, a band around depth discontinuities
(edges of people), the stereo shadow (background pixels the right imager cannot see, left of near objects) and
readings outside the [min, max] range.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from sid.checks import check_number, check_numbers, check_whole
from sid.errors import InputError

__all__ = ["DepthNoise", "KeypointNoise", "visible_to_right_imager"]


@dataclass(frozen=True)
class DepthNoise:
    """Parameters of the depth noise (metres, pixels, probabilities in [0, 1]).

    subpixel: disparity RMS error (px). baseline_m: stereo baseline (m). focal_px: depth focal length (px), None:
    take the depth camera's fx. correlation_px: Gaussian correlation length of the noise (px, 0 = independent
    pixels). hole_fraction: probability that any pixel is a hole. edge_holes: probability that a pixel within
    ``edge_width_px`` (a whole number >= 1; ``edge_holes`` 0 turns these holes off) of a depth jump larger than
    ``edge_jump_m`` is a hole. stereo_shadow: invalidate pixels the right imager cannot see (the right imager sits
    ``baseline_m`` along +x of the depth camera). min_range_m, max_range_m: readings outside are dropped (D435
    minimum distance ~0.28 m at 848x480, ~10 m useful range). depth_unit_m: quantisation step (the D435 default
    depth unit is 1 mm; 0 disables quantisation).
    """

    subpixel: float = 0.08
    baseline_m: float = 0.05
    focal_px: float | None = None
    correlation_px: float = 0.0
    hole_fraction: float = 0.005
    edge_holes: float = 0.5
    edge_width_px: int = 2
    edge_jump_m: float = 0.10
    stereo_shadow: bool = True
    min_range_m: float = 0.28
    max_range_m: float = 10.0
    depth_unit_m: float = 0.001

    def __post_init__(self) -> None:
        check_numbers("depth noise", self, ("subpixel", "correlation_px", "min_range_m", "depth_unit_m"), low=0)
        check_numbers("depth noise", self, ("baseline_m", "edge_jump_m"), low=0, low_open=True)
        check_number("depth noise", "max_range_m", self.max_range_m, low=0, low_open=True, allow_inf=True)
        check_numbers("depth noise", self, ("hole_fraction", "edge_holes"), low=0, high=1)
        if self.focal_px is not None:
            check_number("depth noise", "focal_px", self.focal_px, low=0, low_open=True)
        check_whole("depth noise", "edge_width_px", self.edge_width_px, low=1)
        if self.max_range_m <= self.min_range_m:
            raise InputError("depth noise: max_range_m must exceed min_range_m")

    @classmethod
    def exact(cls) -> DepthNoise:
        """No noise, no holes, no quantisation, no range limits: the rendered depth as is."""
        return cls(
            subpixel=0.0,
            hole_fraction=0.0,
            edge_holes=0.0,
            stereo_shadow=False,
            min_range_m=0.0,
            max_range_m=float("inf"),
            depth_unit_m=0.0,
        )

    def rms(self, depth_m: np.ndarray | float, focal_px: float) -> np.ndarray:
        """RMS depth error (m) at depth ``depth_m`` (m) for a camera of focal length ``focal_px`` (used when the
        record's own ``focal_px`` is None)."""
        focal = self.focal_px if self.focal_px is not None else focal_px
        return np.square(depth_m) * self.subpixel / (focal * self.baseline_m)

    def apply(
        self, depth_m: np.ndarray, focal_px: float, rng: np.random.Generator, image_focal_px: float | None = None
    ) -> np.ndarray:
        """A noisy, holed, quantised copy of an exact (H, W) depth image (m, 0 = none) as float32 metres.

        focal_px: the stereo imagers' focal length (px) for the error model (unless ``self.focal_px`` is set).
        image_focal_px: focal length of the image's own pixel grid (default ``focal_px``), which sets the width of
        the stereo shadow in pixels when the depth is registered to a camera with another resolution.
        """
        exact = np.asarray(depth_m, dtype=np.float32)
        valid = exact > 0
        noisy = exact.copy()
        if self.subpixel > 0:
            noisy += self._unit_noise(exact.shape, rng) * self.rms(exact, focal_px).astype(np.float32)
        if self.depth_unit_m > 0:
            noisy = np.round(noisy / self.depth_unit_m) * np.float32(self.depth_unit_m)
        keep = valid & (noisy >= self.min_range_m) & (noisy <= self.max_range_m)
        if self.hole_fraction > 0:
            keep &= rng.random(exact.shape) >= self.hole_fraction
        if self.edge_holes > 0:
            keep &= ~(
                _edge_band(exact, self.edge_jump_m, self.edge_width_px) & (rng.random(exact.shape) < self.edge_holes)
            )
        if self.stereo_shadow:
            grid_focal = image_focal_px if image_focal_px is not None else focal_px
            keep &= visible_to_right_imager(exact, grid_focal * self.baseline_m)
        return np.where(keep, noisy, np.float32(0.0)).astype(np.float32)

    def _unit_noise(self, shape: tuple[int, ...], rng: np.random.Generator) -> np.ndarray:
        """Zero-mean, unit-variance Gaussian noise, correlated over ``correlation_px`` pixels."""
        white = rng.standard_normal(shape, dtype=np.float32)
        if self.correlation_px <= 0:
            return white
        size = 2 * int(np.ceil(3 * self.correlation_px)) + 1
        kernel = cv2.getGaussianKernel(size, self.correlation_px)
        blurred = cv2.sepFilter2D(white, -1, kernel, kernel, borderType=cv2.BORDER_REFLECT)
        return blurred / np.float32(np.sum(kernel**2))  # 2D kernel k k^T: variance sum(k^2)^2, so std sum(k^2)


def visible_to_right_imager(depth_m: np.ndarray, focal_baseline: float) -> np.ndarray:
    """(H, W) bool: pixels of a left-imager depth image that the right imager also sees.

    A pixel at column u with depth z appears in the right image at u - f*B/z. It is hidden there when a pixel
    further right lands at or left of that position (a nearer surface covers it), or when it falls off the
    image; this is the invalid band a D400 shows left of near objects and along the image's left edge.
    Pixels without depth (0) count as infinitely far and stay as they are (False only if they were covered).
    """
    depth = np.asarray(depth_m, dtype=np.float64)
    with np.errstate(divide="ignore"):
        disparity = np.where(depth > 0, focal_baseline / depth, 0.0)
    right_u = np.arange(depth.shape[1], dtype=np.float64) - disparity
    # Smallest right-image position among the pixels to the right of each pixel.
    following = np.minimum.accumulate(right_u[:, ::-1], axis=1)[:, ::-1]
    nearest_right = np.concatenate([following[:, 1:], np.full((depth.shape[0], 1), np.inf)], axis=1)
    return (right_u < nearest_right) & (right_u >= -0.5)


def _edge_band(depth_m: np.ndarray, jump_m: float, width_px: int) -> np.ndarray:
    """(H, W) bool: pixels within ``width_px`` of a depth jump larger than ``jump_m`` (0 = no depth is far)."""
    depth = np.where(depth_m > 0, depth_m, np.float32(1e3))
    edges = np.zeros(depth.shape, dtype=bool)
    jump_x = np.abs(np.diff(depth, axis=1)) > jump_m
    jump_y = np.abs(np.diff(depth, axis=0)) > jump_m
    edges[:, 1:] |= jump_x
    edges[:, :-1] |= jump_x
    edges[1:, :] |= jump_y
    edges[:-1, :] |= jump_y
    if width_px > 1:
        kernel = np.ones((2 * width_px - 1, 2 * width_px - 1), np.uint8)
        edges = cv2.dilate(edges.astype(np.uint8), kernel).astype(bool)
    return edges


@dataclass(frozen=True)
class KeypointNoise:
    """2D keypoint errors of a pose model: Gaussian pixel noise ``sigma_px`` (colour pixels, per axis) and the
    probability ``drop`` that a keypoint is missed (reported with a low score)."""

    sigma_px: float = 2.0
    drop: float = 0.02

    def __post_init__(self) -> None:
        check_number("keypoint noise", "sigma_px", self.sigma_px, low=0)
        check_number("keypoint noise", "drop", self.drop, low=0, high=1)

    def apply(self, pixels: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """(N, 2) exact pixels -> (noisy (N, 2) pixels, kept (N,) bool)."""
        pixels = np.asarray(pixels, dtype=float)
        noisy = pixels + rng.normal(0.0, self.sigma_px, pixels.shape) if self.sigma_px > 0 else pixels.copy()
        kept = rng.random(len(pixels)) >= self.drop
        return noisy, kept
