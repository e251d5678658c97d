"""Depth-to-colour alignment (dense) and depth lookup at colour pixels (sparse).

The paper's three equations, per valid depth pixel (u_d, v_d) with depth d (metres, depth camera frame):

    p_d = d * K_d^-1 [u_d, v_d, 1]^T        deproject with the depth intrinsics
    p_c = R p_d + t                         move into the colour camera frame (``calib.depth_to_color``)
    [u_c, v_c] = pi(K_c p_c)                project with the colour intrinsics

Pixel coordinates follow librealsense (and ``sid.perception.camera``): (0, 0) is the centre of the top-left pixel, so
the colour pixel hit by (u_c, v_c) is (floor(u_c + 0.5), floor(v_c + 0.5)).

Two splat modes decide which colour pixels a depth pixel writes:

- ``"point"``: the pixel centre only, exactly the paper's equations. Upsampling leaves holes: with D435i-like
  intrinsics (848x480 depth with its wider field of view into 1280x720 colour, ~2.1 colour pixels per depth pixel)
  only about a fifth of the colour pixels get a value (docs/parameters.md).
- ``"rectangle"`` (default): librealsense's convention (``align_images`` in src/proc/align.cpp): project the depth
  pixel's top-left corner (u_d - 0.5, v_d - 0.5) and bottom-right corner (u_d + 0.5, v_d + 0.5), both at the pixel's
  depth, round each to the nearest colour pixel and fill the inclusive rectangle between them; cells outside the
  image are skipped. Dense output, the image a RealSense user gets from ``rs.align`` (tests/sources/test_realsense.py
  compares the two pixel by pixel). librealsense rounds with a cast toward zero, so corners between -1 and -0.5 land
  on row/column 0 there (we floor), and float rounding of corners that fall within ~1e-4 px of a pixel boundary
  moves a few rectangle edges by one pixel. Neighbouring rectangles overlap by up to one pixel, so a near surface
  grows by up to one colour pixel into a far one.

The default is the rectangle: a dense image is what pictures, overlays and any full-frame consumer need, and it can
be checked against librealsense. Keypoint depth does not need the full frame at all (``depth_at_color_pixels``).

Where several depth pixels write one colour pixel the nearest wins (a z-buffer on the stored value); colour pixels
nothing lands on stay 0. Invalid depth is 0 or NaN.

Stored value (``value=``): ``"z"`` (default) stores z of the point in the colour camera frame, which is what
deprojecting a colour pixel with K_c needs (p_c = z * K_c^-1 [u_c, v_c, 1]). ``"depth"`` stores the depth pixel's
own reading, which is what librealsense writes. They differ by (R p_d + t)_z - d, which grows with the rotation and
the lateral offset of the point: centimetres for a 1-degree rotation at 3-6 m (docs/parameters.md), proportionally
less for the near-identity rotation of a factory-calibrated D435i.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

import cv2
import numpy as np

from sid.errors import InputError
from sid.perception.camera import Calibration, Intrinsics, pixel_rays

__all__ = [
    "Aligner",
    "PatchMethod",
    "Search",
    "SplatMode",
    "StoredValue",
    "align_depth_to_color",
    "check_depth_image",
    "depth_at_color_pixels",
]

SplatMode = Literal["rectangle", "point"]
StoredValue = Literal["z", "depth"]
PatchMethod = Literal["nearest", "min", "median"]
Search = Literal["exact", "window"]

# "nearest" patch reduction: sorted depths in a patch split into surfaces where consecutive values differ by more
# than max(_GAP_ABS, _GAP_REL * depth). Intel specifies the D435's depth error below 2 % of the distance up to 2 m,
# so consecutive sorted samples of one surface are far closer than this, while a person in front of a wall is
# separated by tens of centimetres or more.
_GAP_ABS = 0.10
_GAP_REL = 0.05
# A surface needs this many pixels in the patch (fewer if the patch has fewer valid pixels) so that one flying
# pixel at a silhouette edge does not decide the depth.
_MIN_SUPPORT = 3
# Anything beyond this (metres) is an empty z-buffer cell.
_FAR = 1.0e6
# ``_reduce_patches``: a row of c sorted readings has its middle ones at (c - 1) // 2 and c // 2.
_LOW_HIGH = np.array([[1], [0]])
# Every n-th depth pixel is enough to find the most common rectangle size.
_CLASS_SAMPLE = 16
# ``search="window"``: fixed-point steps from a colour pixel to the depth pixel it sees (the first from infinity).
_WINDOW_STEPS = 3


def check_depth_image(depth_m: np.ndarray, intr: Intrinsics, what: str) -> np.ndarray:
    """``depth_m`` as an array after checking it is a 2-D float image (metres) of the size ``intr`` gives; ValueError
    naming ``what`` (the caller) otherwise."""
    depth_m = np.asarray(depth_m)
    if depth_m.ndim != 2:
        raise InputError(f"{what}: depth must be a 2-D image, got shape {depth_m.shape}")
    if depth_m.shape != (intr.height, intr.width):
        raise InputError(
            f"{what}: depth image is {depth_m.shape[1]}x{depth_m.shape[0]} but the calibration says "
            f"{intr.width}x{intr.height}"
        )
    if depth_m.dtype.kind != "f":  # floating (np.issubdtype costs more than the lookups it guards)
        raise InputError(f"{what}: depth must be float metres, got dtype {depth_m.dtype} (multiply by depth_scale)")
    return depth_m


def _check_options(mode: SplatMode, value: StoredValue) -> None:
    """ValueError naming an unknown splat ``mode`` or stored ``value``."""
    if mode not in ("rectangle", "point"):
        raise InputError(f"unknown splat mode {mode!r}; use 'rectangle' or 'point'")
    if value not in ("z", "depth"):
        raise InputError(f"unknown stored value {value!r}; use 'z' or 'depth'")


def _reduce_patches(values: np.ndarray, method: PatchMethod, min_support: int = _MIN_SUPPORT) -> np.ndarray:
    """(N, P) patch depths (NaN = no reading) -> (N,) one depth per patch, NaN where the patch has no reading.

    ``"nearest"``: median of the nearest surface with at least ``min_support`` readings, or the largest one
    (see ``_GAP_*`` and ``_MIN_SUPPORT``).
    ``"min"``: the smallest reading (what the paper's authors did over a 5x5 patch). ``"median"``: plain median.
    """
    n, p = values.shape
    if n == 0 or p == 0:
        return np.full(n, np.nan)
    ordered = np.sort(values, axis=1)  # NaN sorts last
    # The readings of a row are its first ``count`` sorted values (the callers keep only finite readings > 0).
    count = np.isfinite(ordered).sum(axis=1)
    if method == "min":
        return np.where(count > 0, ordered[:, 0], np.nan)
    if method not in ("nearest", "median"):
        raise InputError(f"unknown patch method {method!r}; use 'nearest', 'min' or 'median'")
    # The indices of the two middle readings of each row, (2, N) (a row without readings reads cell -1, which the
    # last line replaces).
    middle = (count - _LOW_HIGH) // 2
    if method == "nearest":
        # Depth jumps between consecutive sorted readings, found in one pass over the flat array (a pair that spans
        # two rows is no jump: skipped below). A row without a jump is one surface. Rows with jumps (silhouette
        # edges, a few per frame) choose their surface in Python, from the jump positions, and read its middle.
        flat = ordered.reshape(-1)
        jumps = np.flatnonzero(flat[1:] - flat[:-1] > np.maximum(_GAP_ABS, _GAP_REL * flat[:-1]))
        if len(jumps):
            chosen = _nearest_surfaces(jumps.tolist(), p, count.tolist(), min_support)
            middle[:, list(chosen)] = [
                [start + (size - 1) // 2 for start, size in chosen.values()],
                [start + size // 2 for start, size in chosen.values()],
            ]
    return np.where(count > 0, 0.5 * ordered[np.arange(n), middle].sum(axis=0), np.nan)


def _nearest_surfaces(jumps: list[int], p: int, count: list[int], min_support: int) -> dict[int, tuple[int, int]]:
    """(start, size) of the surface ``_reduce_patches`` chooses in each sorted row (of ``p`` readings) with depth
    jumps, by row.

    jumps: flat positions row * p + j of the jumps between sorted readings j and j + 1, in order (j = p - 1, a pair
    across two rows, is ignored); count: readings per row. A row's surfaces run between its jumps; the chosen one
    is the nearest holding at least ``min_support`` readings, or the nearest of the largest when none does.
    """
    bounds: dict[int, list[int]] = {}
    for position in jumps:
        row, j = divmod(position, p)
        if j < p - 1:
            bounds.setdefault(row, [0]).append(j + 1)
    chosen = {}
    for row, starts in bounds.items():
        ends = [*starts[1:], count[row]]
        sizes = [end - first for first, end in zip(starts, ends, strict=True)]
        support = min(min_support, max(sizes))
        k = next(k for k, length in enumerate(sizes) if length >= support)
        chosen[row] = starts[k], sizes[k]
    return chosen


def _patch_offsets(patch: int) -> tuple[np.ndarray, np.ndarray]:
    half = patch // 2
    dv, du = np.mgrid[-half : half + 1, -half : half + 1]
    return du.ravel(), dv.ravel()


def _check_pixels(pixels: np.ndarray, patch: int) -> np.ndarray:
    if isinstance(patch, bool) or not isinstance(patch, (int, np.integer)) or patch < 1 or patch % 2 == 0:
        raise InputError(f"patch must be a positive odd integer (pixels), got {patch!r}")
    pixels = np.asarray(pixels, dtype=float)
    if pixels.size == 0:
        return pixels.reshape(0, 2)
    if pixels.ndim != 2 or pixels.shape[1] != 2:
        raise InputError(f"pixels must be an (N, 2) array of (u, v) colour pixels, got shape {pixels.shape}")
    return pixels


def _registered_patches(
    depth_m: np.ndarray, pixels: np.ndarray, patch: int, depth_min: float, depth_max: float
) -> np.ndarray:
    """(N, patch*patch) depths around each (rounded) pixel; NaN outside the image, at NaN pixels and at readings
    outside [depth_min, depth_max] (metres; 0, NaN and inf among them: no reading)."""
    h, w = depth_m.shape
    finite = np.all(np.isfinite(pixels), axis=1)
    centre = np.floor(np.where(finite[:, None], pixels, -(10**6)) + 0.5).astype(np.int64)
    du, dv = _patch_offsets(patch)
    u = centre[:, :1] + du[None, :]
    v = centre[:, 1:] + dv[None, :]
    inside = (u >= 0) & (u < w) & (v >= 0) & (v < h)
    values = depth_m[np.clip(v, 0, h - 1), np.clip(u, 0, w - 1)].astype(float)
    with np.errstate(invalid="ignore"):
        values[~inside | ~((values >= depth_min) & (values <= depth_max))] = np.nan
    return values


def _window_blocks(depth_m: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Depth blocks covering each window lo..hi (inclusive (u, v)), all of the largest window's size.

    Returns (N, h, w) readings and their (N, 2) top-left (u, v). A block can exceed its own window (never the
    image): more candidates than needed, which the caller handles exactly anyway. One fancy index into a sliding-
    window view copies all blocks at once.
    """
    height, width = depth_m.shape
    w = int(min((hi[:, 0] - lo[:, 0]).max() + 1, width))
    h = int(min((hi[:, 1] - lo[:, 1]).max() + 1, height))
    corner = np.minimum(lo, [width - w, height - h])
    blocks = np.lib.stride_tricks.sliding_window_view(depth_m, (h, w))[corner[:, 1], corner[:, 0]]
    return blocks, corner


@dataclass(frozen=True)
class _Projection:
    """Colour-image coordinates of depth points: u, v (pixels) and z (metres, colour frame)."""

    u: np.ndarray
    v: np.ndarray
    z: np.ndarray


def _project_depth_points(
    u_d: np.ndarray, v_d: np.ndarray, d: np.ndarray, calib: Calibration, dtype: type = np.float64
) -> _Projection:
    """Depth pixels (u_d, v_d) with readings d (metres) -> colour pixels and colour-frame z (the three equations)."""
    assert calib.depth is not None
    kd, kc = calib.depth, calib.color
    r, t = calib.depth_to_color.rotation, calib.depth_to_color.translation
    x, y = pixel_rays(u_d, v_d, kd)
    # p_c = d * (R @ [x, y, 1]) + t, then K_c: homogeneous colour pixel = d * (K_c R ray) + K_c t.
    m = kc.K @ r
    b = kc.K @ t
    hx = d * (m[0, 0] * x + m[0, 1] * y + m[0, 2]) + b[0]
    hy = d * (m[1, 0] * x + m[1, 1] * y + m[1, 2]) + b[1]
    z = d * (m[2, 0] * x + m[2, 1] * y + m[2, 2]) + b[2]
    with np.errstate(divide="ignore", invalid="ignore"):
        return _Projection((hx / z).astype(dtype), (hy / z).astype(dtype), z.astype(dtype))


def _search_windows(
    pixels: np.ndarray, patch: int, calib: Calibration, depth_min: np.ndarray | float, depth_max: np.ndarray | float
) -> tuple[np.ndarray, np.ndarray]:
    """Per colour pixel, the inclusive depth-image window (lo, hi as (u, v)) that can land in its colour patch.

    The colour patch (a square of ``patch`` pixels, half a pixel beyond the outer centres) seen between depth_min and
    depth_max is a frustum; its image in the depth camera is the convex hull of its 8 projected corners (the
    epipolar band of the patch). A depth pixel reaches half a pixel around its centre, so the window is that hull's
    bounding box widened by half a pixel and rounded outwards.
    """
    assert calib.depth is not None
    kc, kd = calib.color, calib.depth
    half = patch // 2 + 0.5
    centre = np.floor(pixels + 0.5)
    # Rays through the patch's 4 corners, (4, N) per component; colour-frame point = z * (x, y, 1).
    corner_u, corner_v = np.array([-half, half, -half, half])[:, None], np.array([-half, -half, half, half])[:, None]
    x, y = pixel_rays(centre[:, 0] + corner_u, centre[:, 1] + corner_v, kc)
    # Depth-frame point R^T (p_c - t) = z * (R^T ray) - R^T t.
    rt = calib.depth_to_color.rotation.T
    shift = rt @ calib.depth_to_color.translation
    ray = [rt[i, 0] * x + rt[i, 1] * y + rt[i, 2] for i in range(3)]
    u_parts, v_parts = [], []
    for z in (np.asarray(depth_min, dtype=float), np.asarray(depth_max, dtype=float)):
        px, py, pz = (z * ray[i] - shift[i] for i in range(3))
        u_parts.append(px / pz * kd.fx + kd.cx)
        v_parts.append(py / pz * kd.fy + kd.cy)
    ud, vd = np.concatenate(u_parts), np.concatenate(v_parts)  # (8, N)
    lo = np.floor(np.stack([ud.min(axis=0), vd.min(axis=0)], axis=1) - 0.5)
    hi = np.ceil(np.stack([ud.max(axis=0), vd.max(axis=0)], axis=1) + 0.5)
    lo = np.clip(lo, 0, [kd.width - 1, kd.height - 1]).astype(np.int64)
    hi = np.clip(hi, 0, [kd.width - 1, kd.height - 1]).astype(np.int64)
    return lo, hi


class Aligner:
    """Depth-to-colour alignment for one calibration, with everything that depends only on it precomputed.

    Per depth pixel the colour-camera ray K_c R K_d^-1 [u, v, 1] (at the centre and, for rectangle splatting, at
    the two corners) is stored as float32, so a frame costs one multiply-add per coordinate, a division, rounding
    and the z-buffer. Reuse one Aligner for a stream; ``align_depth_to_color`` builds a throw-away one.

    Z-buffer: ``np.minimum.at`` on the flat colour image (numpy >= 1.25 made it fast; faster than repeated fancy
    assignment or sorting by depth, docs/parameters.md).
    Rectangles are not enumerated cell by cell (a 848x480 -> 1280x720 D435i pair gives 9-16 cells per depth pixel):
    most rectangles have the same size (3x3 cells there), and a larger one is the union of 2-4 such base rectangles.
    Base rectangles are z-buffered at their top-left cells, then one grey-level erosion (OpenCV's min filter) with the
    base rectangle as kernel spreads each minimum over its rectangle; the few smaller rectangles are written cell by
    cell. This is exactly the minimum over all rectangles covering a pixel (tests compare with a per-pixel loop).
    """

    def __init__(self, calib: Calibration, mode: SplatMode = "rectangle", value: StoredValue = "z") -> None:
        if calib.depth is None:
            raise InputError("Aligner: the calibration has no depth intrinsics (depth already registered to colour)")
        _check_options(mode, value)
        self.calib, self.mode, self.value = calib, mode, value
        kd, kc = calib.depth, calib.color
        m = kc.K @ calib.depth_to_color.rotation
        self._offset = [np.float32(x) for x in kc.K @ calib.depth_to_color.translation]
        v, u = np.mgrid[0 : kd.height, 0 : kd.width].astype(np.float64)

        def rays(shift: float) -> np.ndarray:
            x, y = (a.ravel() for a in pixel_rays(u + shift, v + shift, kd))
            return (m[:, :2] @ np.stack([x, y]) + m[:, 2:]).astype(np.float32)  # (3, H_d * W_d)

        self._centre = rays(0.0) if mode == "point" or value == "z" else None
        self._corners = (rays(-0.5), rays(0.5)) if mode == "rectangle" else None
        # Scratch buffers reused across frames: fresh multi-megabyte arrays per frame cost more in page faults
        # than the arithmetic. An Aligner is therefore not thread-safe; use one per thread.
        self._work = np.empty((8, kd.height * kd.width), dtype=np.float32)
        self._image = np.empty((1, kc.height * kc.width), dtype=np.float32)
        self._canvas = np.empty(0, dtype=np.float32)

    def __call__(self, depth_m: np.ndarray) -> np.ndarray:
        """Depth image (H_d, W_d) metres -> (H_c, W_c) float32 metres in the colour grid, 0 where nothing landed."""
        assert self.calib.depth is not None
        depth_m = check_depth_image(depth_m, self.calib.depth, "align")
        d = self._work[0]
        np.fmax(depth_m.reshape(-1), np.float32(0), out=d)  # NaN and negative -> 0 (no reading)
        out = self._points(d) if self._corners is None else self._rectangles(d)
        # Empty cells hold +inf: threshold them to zero (OpenCV, one SIMD pass, also allocates the result).
        return cv2.threshold(out, _FAR, 0.0, cv2.THRESH_TOZERO_INV)[1]

    def _project(self, d: np.ndarray, rays: np.ndarray, z: np.ndarray, u: np.ndarray, v: np.ndarray) -> None:
        """Colour-frame z (metres) and colour pixel (u, v) of every depth pixel along ``rays``, into z, u, v."""
        b = self._offset
        np.multiply(d, rays[2], out=z)
        z += b[2]
        with np.errstate(divide="ignore", invalid="ignore"):
            for axis, target in ((0, u), (1, v)):
                np.multiply(d, rays[axis], out=target)
                target += b[axis]
                target /= z

    def _stored(self, d: np.ndarray, out: np.ndarray) -> np.ndarray:
        """The value written per depth pixel: colour-frame z or the depth reading itself (metres)."""
        if self.value == "depth":
            return d
        assert self._centre is not None
        np.multiply(d, self._centre[2], out=out)
        out += self._offset[2]
        return out

    def _points(self, d: np.ndarray) -> np.ndarray:
        kc = self.calib.color
        assert self._centre is not None
        z, u, v = self._work[1:4]
        self._project(d, self._centre, z, u, v)
        with np.errstate(invalid="ignore"):
            for coord in (u, v):
                coord += 0.5
                np.floor(coord, out=coord)
            valid = (d > 0) & (z > 0) & (u >= 0) & (u < kc.width) & (v >= 0) & (v < kc.height)
        keep = np.flatnonzero(valid)
        # Flat indices in int64: float32 holds integers exactly only up to 2^24, fewer than a large image's pixels.
        cell = v[keep].astype(np.int64)
        cell *= kc.width
        cell += u[keep].astype(np.int64)
        out = self._image[0]
        out.fill(np.inf)
        np.minimum.at(out, cell, z[keep] if self.value == "z" else d[keep])
        return out.reshape(kc.height, kc.width)

    def _rectangles(self, d: np.ndarray) -> np.ndarray:
        """Rectangle splat (see the class docstring): (H_c, W_c) float32, +inf where nothing landed."""
        assert self._corners is not None
        kc = self.calib.color
        z0, x0, y0, z1, x1, y1, stored = self._work[1:8]
        self._project(d, self._corners[0], z0, x0, y0)
        self._project(d, self._corners[1], z1, x1, y1)
        with np.errstate(invalid="ignore"):
            valid = (d > 0) & (z0 > 0) & (z1 > 0)
            for coord in (x0, y0, x1, y1):
                coord += 0.5
                np.floor(coord, out=coord)
            # Keep rectangles that touch the image; their outside cells are dropped (librealsense skips them too).
            valid &= (x1 >= 0) & (y1 >= 0) & (x0 < kc.width) & (y0 < kc.height) & (x0 <= x1) & (y0 <= y1)
            x1 -= x0  # rectangle size - 1 per axis (float32 holds these integers exactly)
            y1 -= y0
        keep = np.flatnonzero(valid)
        stored = self._stored(d, stored)[keep]
        span_x, span_y, x0, y0 = (a[keep] for a in (x1, y1, x0, y0))
        # Work on a canvas padded by the largest rectangle, so that no rectangle needs clipping.
        pad = int(max(span_x.max(initial=0), span_y.max(initial=0))) + 1
        width, height = kc.width + 2 * pad, kc.height + 2 * pad
        cell = (y0.astype(np.int64) + pad) * width + (x0.astype(np.int64) + pad)  # top-left cell, padded canvas
        # Every rectangle at least as large as the base size (the most common one, from a subsample) is the union of
        # base-size rectangles at 1-4 offsets; those are z-buffered at their top-left cells and one grey erosion with
        # the base rectangle (bottom-right anchor: out[q] = min over corners c in [q - base, q]) spreads them.
        sample = (span_y[::_CLASS_SAMPLE] * pad + span_x[::_CLASS_SAMPLE]).astype(np.int64)
        base_y, base_x = divmod(int(np.argmax(np.bincount(sample))), pad) if sample.size else (0, 0)
        extra_x, extra_y = span_x - base_x, span_y - base_y
        covered = (extra_x >= 0) & (extra_y >= 0)
        canvas = self._canvas_of(height * width)
        for oy in range(int(extra_y.max(initial=0)) + 1):
            for ox in range(int(extra_x.max(initial=0)) + 1):
                if ox == 0 and oy == 0:
                    sel = slice(None) if covered.all() else np.flatnonzero(covered)
                else:
                    sel = np.flatnonzero((extra_x >= ox) & (extra_y >= oy))
                np.minimum.at(canvas, cell[sel] + (oy * width + ox), stored[sel])
        image = canvas.reshape(height, width)
        if base_x or base_y:
            kernel = np.ones((base_y + 1, base_x + 1), np.uint8)
            image = cv2.erode(
                image, kernel, anchor=(base_x, base_y), borderType=cv2.BORDER_CONSTANT, borderValue=np.inf
            )
        # Rectangles smaller than the base size in some axis (rare) are written cell by cell.
        rest = np.flatnonzero(~covered)
        for oy in range(int(span_y[rest].max(initial=-1)) + 1):
            for ox in range(int(span_x[rest].max(initial=-1)) + 1):
                sel = rest[(span_x[rest] >= ox) & (span_y[rest] >= oy)]
                np.minimum.at(image.reshape(-1), cell[sel] + (oy * width + ox), stored[sel])
        return image[pad : pad + kc.height, pad : pad + kc.width]

    def _canvas_of(self, size: int) -> np.ndarray:
        """A flat float32 scratch canvas of ``size`` cells filled with +inf (grown on demand)."""
        if self._canvas.size < size:
            self._canvas = np.empty(size, dtype=np.float32)
        canvas = self._canvas[:size]
        canvas.fill(np.inf)
        return canvas


def align_depth_to_color(
    depth_m: np.ndarray, calib: Calibration, mode: SplatMode = "rectangle", value: StoredValue = "z"
) -> np.ndarray:
    """Align a depth image (H_d, W_d metres, 0/NaN = none) to the colour image: (H_c, W_c) float32 metres.

    See the module docstring for ``mode`` and ``value``. Registered depth (``calib.depth`` None) is returned as a
    float32 copy with NaN set to 0. For a stream, build one ``Aligner`` and call it per frame.
    """
    if calib.depth is None:
        depth_m = check_depth_image(depth_m, calib.color, "align_depth_to_color")
        return np.nan_to_num(depth_m.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0)
    return Aligner(calib, mode, value)(depth_m)


def depth_at_color_pixels(
    depth_m: np.ndarray,
    pixels: np.ndarray,
    calib: Calibration,
    patch: int = 5,
    *,
    method: PatchMethod = "nearest",
    mode: SplatMode = "rectangle",
    value: StoredValue = "z",
    depth_min: float = 0.1,
    depth_max: float = 10.0,
    search: Search = "exact",
) -> np.ndarray:
    """Depth (metres, colour camera z) at colour pixels, robust to holes and silhouette edges.

    depth_m: the frame's depth (float metres, 0/NaN = no reading), registered to colour when ``calib.depth`` is
    None, else in the depth camera's grid. pixels: (N, 2) colour pixels (u, v); a NaN pixel gives NaN.
    Returns (N,) metres, NaN where the ``patch`` x ``patch`` window around the pixel holds no valid depth: a reading
    outside [``depth_min``, ``depth_max``] (metres) is no reading, registered or not.

    Reduction (``method``): ``"nearest"`` (default) sorts the patch's readings, splits them into surfaces at depth
    jumps and returns the median of the nearest surface with at least 3 pixels: a keypoint on a person's silhouette
    keeps the person, not the wall behind, and one flying pixel or a noise spike does not decide. ``"min"`` is what
    the paper's authors did (minimum over 5x5), which follows single outliers; ``"median"`` mixes surfaces at edges.

    Unregistered depth is looked up sparsely, without aligning the frame: the depth pixels whose 3D points can land
    in a pixel's colour patch lie in the patch's epipolar band between ``depth_min`` and ``depth_max`` (metres; the
    D435 sees from ~0.1 m). The readings present in that band narrow the depth range and so the band (usually to a
    few pixels); only those depth pixels go through the exact forward transform (same ``mode``/``value`` as
    ``Aligner``), are z-buffered per colour pixel of the patch and reduced as above. The result equals aligning the
    whole frame and reading the patch (tests check it), for readings within [depth_min, depth_max]. This is the
    colour-pixel-to-depth search of librealsense's ``rs2_project_color_pixel_to_depth_pixel``, done for a whole
    patch at once and with the same splat as the dense alignment.

    ``search="window"`` (what ``sid.perception.lifting`` uses per frame; several times faster) skips the search: from
    the colour pixel's ray, ``_WINDOW_STEPS`` fixed-point steps (the first at infinite depth, then at the depth found)
    find the depth pixel the ray meets, and the readings of the depth window about as wide as the colour patch
    around it (3x3 for a 5x5 patch and D435i intrinsics), as colour-frame z (``value``), are reduced as above.
    What depends only on the calibration (each depth pixel's colour-frame z per metre of reading) is kept for the
    last few calibrations.
    It reads the depth image's own pixels instead of the splatted patch, so it is not identical: ``sid bench``'s
    ``align/window_4x17`` times both and reports their median difference (docs/benchmarks.md, "Depth at the
    keypoints"); tests/perception/test_align.py bounds it against the dense alignment. ``mode`` only applies to
    the exact search.
    """
    if search not in ("exact", "window"):
        raise InputError(f"unknown depth search {search!r}; use 'exact' or 'window'")
    _check_options(mode, value)
    if not (0 < depth_min < depth_max and math.isfinite(depth_max)):
        raise InputError(f"need 0 < depth_min < depth_max < inf, got {depth_min}, {depth_max}")
    pixels = _check_pixels(pixels, patch)
    if calib.depth is None:
        depth_m = check_depth_image(depth_m, calib.color, "depth_at_color_pixels")
        if len(pixels) == 0:
            return np.zeros(0)
        return _reduce_patches(_registered_patches(depth_m, pixels, patch, depth_min, depth_max), method)
    depth_m = check_depth_image(depth_m, calib.depth, "depth_at_color_pixels")
    if len(pixels) == 0:
        return np.zeros(0)
    if search == "window":
        return _window_depth(depth_m, pixels, calib, patch, method, value, depth_min, depth_max)
    return _reduce_patches(
        _unregistered_patches(depth_m, pixels, calib, patch, mode, value, depth_min, depth_max), method
    )


@dataclass(frozen=True)
class _WindowGeometry:
    """What ``search="window"`` needs of one calibration and patch size, computed once (``_window_geometry``).

    du, dv: (C,) the window's cells' offsets from the centre pixel and offsets: (C,) the same as flat indices into
    the depth image; support: the nearest surface's support scaled to C cells; ray_z: (H_d * W_d,) per depth pixel
    (u, v) the colour-frame z of R K_d^-1 [u, v, 1], i.e. per metre of reading; focal, principal: (2, 1) the depth
    intrinsics' (fx, fy) and (cx, cy); interior_start, interior_end: (2, 1) the first centre column and row whose
    window lies inside the image and the first whose window leaves it (as floats: they are compared with float
    pixel coordinates, which is cheaper than with integers).
    """

    du: np.ndarray
    dv: np.ndarray
    offsets: np.ndarray
    support: int
    ray_z: np.ndarray
    focal: np.ndarray
    principal: np.ndarray
    interior_start: np.ndarray
    interior_end: np.ndarray


def _window_geometry(calib: Calibration, patch: int) -> _WindowGeometry:
    """The ``_WindowGeometry`` of a calibration with depth intrinsics, kept for the last few calibrations by the
    values it depends on, not by object: a stream's frames may each carry their own copy of one calibration."""
    kd, kc, rotation = calib.depth, calib.color, calib.depth_to_color.rotation
    assert kd is not None
    depth = (kd.width, kd.height, kd.fx, kd.fy, kd.cx, kd.cy)
    return _cached_window_geometry(depth, (kc.fx, kc.fy), tuple(rotation[2].tolist()), patch)


@lru_cache(maxsize=4)  # a few MB each at 848x480, and ``ray_z`` is slow to build per frame
def _cached_window_geometry(
    depth: tuple[int, int, float, float, float, float],
    color_focal: tuple[float, float],
    rotation_z: tuple[float, ...],
    patch: int,
) -> _WindowGeometry:
    """``_window_geometry`` from the depth intrinsics (width, height, fx, fy, cx, cy), the colour focal lengths
    (fx, fy) and the depth-to-colour rotation's last row."""
    width, height, fx, fy, cx, cy = depth
    # The colour patch spans about patch * fd / fc depth pixels: an odd window at least that wide (at least 1).
    half = max(0, int(np.ceil((patch * max(fx / color_focal[0], fy / color_focal[1]) - 1) / 2)))
    dv, du = (a.ravel() for a in np.mgrid[-half : half + 1, -half : half + 1])
    rows, cols = np.mgrid[0:height, 0:width]
    ray_z = rotation_z[0] * (cols - cx) / fx + rotation_z[1] * (rows - cy) / fy + rotation_z[2]
    support = int(np.ceil(_MIN_SUPPORT * len(du) / patch**2))
    interior = np.array([[half], [half]], dtype=float), np.array([[width - half], [height - half]], dtype=float)
    arrays = (du, dv, dv * width + du, ray_z.ravel(), np.array([[fx], [fy]]), np.array([[cx], [cy]]), *interior)
    for array in arrays:  # shared by every call with this calibration
        array.flags.writeable = False
    return _WindowGeometry(*arrays[:3], support, *arrays[3:])


def _window_depth(
    depth_m: np.ndarray,
    pixels: np.ndarray,
    calib: Calibration,
    patch: int,
    method: PatchMethod,
    value: StoredValue,
    depth_min: float,
    depth_max: float,
) -> np.ndarray:
    """``depth_at_color_pixels(search="window")``: (N,) metres, NaN where the window holds no reading in range."""
    assert calib.depth is not None
    kd, kc = calib.depth, calib.color
    rotation, translation = calib.depth_to_color.rotation, calib.depth_to_color.translation
    geometry = _window_geometry(calib, patch)
    flat = depth_m.reshape(-1)  # a copy only when the image is not contiguous
    shift = (rotation.T @ translation)[:, None]
    low, high = np.float64(depth_min), np.float64(depth_max)
    colour_ray = np.ones((3, len(pixels)))
    z = None  # colour-frame depth of each pixel's surface (NaN: none found yet); the first step looks from infinity
    with np.errstate(divide="ignore", invalid="ignore"):  # NaN pixels, rays that miss the depth camera
        # Colour ray (x, y, 1) per pixel (NaN for a NaN pixel, never seen), in the depth frame: a point at colour
        # depth z is z * ray - R^T t; while z is unknown, the ray's direction.
        colour_ray[:2] = pixel_rays(pixels[:, 0], pixels[:, 1], kc)
        point = ray = rotation.T @ colour_ray
        for step in range(_WINDOW_STEPS):
            index, inside = _window_cells(point, geometry, kd.width, kd.height)
            # In float64 (the image may be float32): comparisons and products with float64 would cast it anyway.
            reading = flat.take(index).astype(np.float64, copy=False)
            valid = (reading >= low) & (reading <= high)
            if inside is not None:
                valid &= inside
            if step == _WINDOW_STEPS - 1:
                break
            # Colour-frame z of each reading's point, (R d K_d^-1 [u, v, 1] + t)_z; the steps only move the window,
            # so the nearest reading will do (NaN: none, the previous z stays).
            nearest = np.fmin.reduce(
                np.where(valid, reading * geometry.ray_z.take(index) + translation[2], np.nan), axis=1
            )
            z = nearest if z is None else np.where(np.isnan(nearest), z, nearest)
            point = np.where(np.isnan(z), ray, z * ray - shift)  # (3, N) in the depth frame
        stored = reading * geometry.ray_z.take(index) + translation[2] if value == "z" else reading
        return _reduce_patches(np.where(valid, stored, np.nan), method, geometry.support)


def _window_cells(
    point: np.ndarray, geometry: _WindowGeometry, width: int, height: int
) -> tuple[np.ndarray, np.ndarray | None]:
    """Flat depth-image indices (N, C) of the window around the depth pixel each point (3, N, depth frame) projects
    to, and which cells lie in the image (None: all of them; cells outside index pixel 0). NaN points have no
    cell in the image (their comparisons are False)."""
    pixel = point[:2] / point[2] * geometry.focal + geometry.principal + 0.5  # (2, N): floor gives the pixel (u, v)
    # Usually every window lies inside the image: one add gives all indices, no per-cell test (the pixels are
    # positive there, so the integer cast floors them).
    if (point[2] > 0.0).all() and ((pixel >= geometry.interior_start) & (pixel < geometry.interior_end)).all():
        centre = pixel.astype(np.intp)
        return (centre[1] * width + centre[0])[:, None] + geometry.offsets, None
    centre = np.floor(pixel)
    u, v = centre[0][:, None] + geometry.du, centre[1][:, None] + geometry.dv
    inside = (u >= 0) & (u < width) & (v >= 0) & (v < height) & (point[2] > 0.0)[:, None]
    return np.where(inside, v * width + u, 0).astype(np.intp), inside


def _unregistered_patches(
    depth_m: np.ndarray,
    pixels: np.ndarray,
    calib: Calibration,
    patch: int,
    mode: SplatMode,
    value: StoredValue,
    depth_min: float,
    depth_max: float,
) -> np.ndarray:
    """(N, patch*patch) aligned depths in each colour patch, computed from a depth window per pixel (NaN = none)."""
    assert calib.depth is not None
    kd, kc = calib.depth, calib.color
    n = len(pixels)
    out = np.full((n, patch * patch), np.inf)
    finite = np.all(np.isfinite(pixels), axis=1)
    if not finite.any():
        return np.full((n, patch * patch), np.nan)
    idx = np.flatnonzero(finite)
    px = pixels[idx]
    centre_px = np.floor(px + 0.5)
    # Two passes. The readings in each pixel's window for the whole [depth_min, depth_max] range (a long epipolar
    # band, mostly for near depths) give the depths actually present there; the window for that range alone is
    # usually a few pixels wide, and only its pixels are projected.
    lo, hi = _search_windows(px, patch, calib, depth_min, depth_max)
    readings = _window_blocks(depth_m, lo, hi)[0].reshape(len(px), -1)
    with np.errstate(invalid="ignore"):
        valid = (readings >= depth_min) & (readings <= depth_max)
    nearest = np.where(valid, readings, np.inf).min(axis=1)
    farthest = np.where(valid, readings, -np.inf).max(axis=1)
    present = np.isfinite(nearest)
    if not present.any():
        return np.full((n, patch * patch), np.nan)
    idx, px, centre_px = idx[present], px[present], centre_px[present]
    lo, hi = _search_windows(px, patch, calib, nearest[present], farthest[present])
    blocks, corner = _window_blocks(depth_m, lo, hi)
    grid_v, grid_u = np.indices(blocks.shape[1:]).reshape(2, -1)
    with np.errstate(invalid="ignore"):
        owner, cells = np.nonzero(((blocks >= depth_min) & (blocks <= depth_max)).reshape(len(px), -1))
    u_d = corner[owner, 0] + grid_u[cells]
    v_d = corner[owner, 1] + grid_v[cells]
    d = blocks.reshape(len(px), -1)[owner, cells].astype(float)
    half = float(patch // 2)
    centre_u, centre_v = centre_px[owner, 0], centre_px[owner, 1]
    # The centre's projection rules out most candidates (the band holds them for every depth in the range): a
    # depth pixel's rectangle reaches about fc / fd / 2 colour pixels around its centre, plus rounding.
    centre = _project_depth_points(u_d, v_d, d, calib)
    reach = half + 1.0 + max(kc.fx / kd.fx, kc.fy / kd.fy)
    with np.errstate(invalid="ignore"):
        near = np.flatnonzero(
            (centre.z > 0) & (np.abs(centre.u - centre_u) <= reach) & (np.abs(centre.v - centre_v) <= reach)
        )
    owner, u_d, v_d, d, centre_u, centre_v = (a[near] for a in (owner, u_d, v_d, d, centre_u, centre_v))
    stored = centre.z[near] if value == "z" else d
    if mode == "point":
        u0 = u1 = centre.u[near]
        v0 = v1 = centre.v[near]
        ok = np.ones(len(near), dtype=bool)
    else:
        corners = _project_depth_points(
            np.concatenate([u_d - 0.5, u_d + 0.5]), np.concatenate([v_d - 0.5, v_d + 0.5]), np.tile(d, 2), calib
        )
        (u0, u1), (v0, v1), (z0, z1) = (np.split(a, 2) for a in (corners.u, corners.v, corners.z))
        with np.errstate(invalid="ignore"):
            ok = (z0 > 0) & (z1 > 0)
    with np.errstate(invalid="ignore"):
        # Inclusive colour-pixel ranges each depth pixel writes, clipped to its patch and to the image.
        col_lo = np.maximum(np.floor(u0 + 0.5), np.maximum(centre_u - half, 0.0))
        col_hi = np.minimum(np.floor(u1 + 0.5), np.minimum(centre_u + half, kc.width - 1.0))
        row_lo = np.maximum(np.floor(v0 + 0.5), np.maximum(centre_v - half, 0.0))
        row_hi = np.minimum(np.floor(v1 + 0.5), np.minimum(centre_v + half, kc.height - 1.0))
        # (patch, S) layouts keep the long axis innermost: numpy loops over short rows are slow.
        offsets = np.arange(-half, half + 1.0)[:, None]
        cols = centre_u + offsets  # colour columns of each candidate's patch
        rows = centre_v + offsets
        covers_col = (cols >= col_lo) & (cols <= col_hi) & ok
        covers_row = (rows >= row_lo) & (rows <= row_hi)
    # Cell (row r, column c) of the patch is r * patch + c, as in _patch_offsets.
    cell, point = np.nonzero((covers_row[:, None, :] & covers_col[None, :, :]).reshape(patch * patch, -1))
    # Flat indices: ufunc.at with a tuple of index arrays is several times slower.
    np.minimum.at(out.reshape(-1), idx[owner[point]] * (patch * patch) + cell, stored[point])
    return np.where(np.isinf(out), np.nan, out)
