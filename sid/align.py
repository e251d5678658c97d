"""Depth-to-colour alignment (dense) and depth lookup at colour pixels (sparse).

The paper's three equations, per valid depth pixel (u_d, v_d) with depth d (metres, depth camera frame):

    p_d = d * K_d^-1 [u_d, v_d, 1]^T        deproject with the depth intrinsics
    p_c = R p_d + t                         move into the colour camera frame (``calib.depth_to_color``)
    [u_c, v_c] = pi(K_c p_c)                project with the colour intrinsics

Pixel coordinates follow librealsense (and ``sid.camera``): (0, 0) is the centre of the top-left pixel, so the
colour pixel hit by (u_c, v_c) is (floor(u_c + 0.5), floor(v_c + 0.5)).

Two splat modes decide which colour pixels a depth pixel writes:

- ``"point"``: the pixel centre only, exactly the paper's equations. Upsampling 848x480 depth into 1280x720 colour
  leaves about half of the colour pixels empty (a depth pixel covers ~1.5 x 1.5 colour pixels).
- ``"rectangle"`` (default): librealsense's convention (``align_images`` in src/proc/align.cpp): project the depth
  pixel's top-left corner (u_d - 0.5, v_d - 0.5) and bottom-right corner (u_d + 0.5, v_d + 0.5), both at the pixel's
  depth, round each to the nearest colour pixel and fill the inclusive rectangle between them. Dense output, the
  same image a RealSense user gets from ``rs.align``. Unlike librealsense, a rectangle that sticks out of the colour
  image is clipped rather than dropped, so border pixels can be filled where librealsense leaves 0.

Where several depth pixels write one colour pixel the nearest wins (a z-buffer on the stored value); colour pixels
nothing lands on stay 0. Invalid depth is 0 or NaN.

Stored value (``value=``): ``"z"`` (default) stores z of the point in the colour camera frame, which is what
deprojecting a colour pixel with K_c needs (p_c = z * K_c^-1 [u_c, v_c, 1]). ``"depth"`` stores the depth pixel's
own reading, which is what librealsense writes; the two differ by (R p_d + t)_z - d, about a millimetre for a D435i
(depth-to-colour rotation well under a degree, translation mostly along x).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from sid.camera import Calibration, Intrinsics

SplatMode = Literal["rectangle", "point"]
StoredValue = Literal["z", "depth"]
PatchMethod = Literal["nearest", "min", "median"]

# "nearest" patch reduction: sorted depths in a patch split into surfaces where consecutive values differ by more
# than max(_GAP_ABS, _GAP_REL * depth). D435 noise at 2 m is ~2 cm RMS, so consecutive sorted samples of one
# surface are far closer than this; a person in front of a wall is separated by tens of centimetres or more.
_GAP_ABS = 0.10
_GAP_REL = 0.05
# A surface needs this many pixels in the patch (fewer if the patch has fewer valid pixels) so that one flying
# pixel at a silhouette edge does not decide the depth.
_MIN_SUPPORT = 3


def _validate_depth(depth_m: np.ndarray, intr: Intrinsics, what: str) -> np.ndarray:
    depth_m = np.asarray(depth_m)
    if depth_m.ndim != 2:
        raise ValueError(f"{what}: depth must be a 2-D image, got shape {depth_m.shape}")
    if depth_m.shape != (intr.height, intr.width):
        raise ValueError(
            f"{what}: depth image is {depth_m.shape[1]}x{depth_m.shape[0]} but the calibration says "
            f"{intr.width}x{intr.height}"
        )
    if not np.issubdtype(depth_m.dtype, np.floating):
        raise ValueError(f"{what}: depth must be float metres, got dtype {depth_m.dtype} (multiply by depth_scale)")
    return depth_m


def _reduce_patches(values: np.ndarray, method: PatchMethod) -> np.ndarray:
    """(N, P) patch depths (NaN = no reading) -> (N,) one depth per patch, NaN where the patch has no reading.

    ``"nearest"``: median of the nearest surface with enough support (see ``_GAP_*`` and ``_MIN_SUPPORT``).
    ``"min"``: the smallest reading (what the paper's authors did over a 5x5 patch). ``"median"``: plain median.
    """
    n, p = values.shape
    result = np.full(n, np.nan)
    if n == 0 or p == 0:
        return result
    ordered = np.sort(values, axis=1)  # NaN sorts last
    count = np.count_nonzero(np.isfinite(ordered), axis=1)
    has = count > 0
    rows = np.arange(n)
    if method == "min":
        result[has] = ordered[has, 0]
        return result
    if method == "median":
        lo, hi = (count - 1) // 2, count // 2
        mid = 0.5 * (ordered[rows, np.maximum(lo, 0)] + ordered[rows, np.maximum(hi, 0)])
        result[has] = mid[has]
        return result
    if method != "nearest":
        raise ValueError(f"unknown patch method {method!r}; use 'nearest', 'min' or 'median'")
    with np.errstate(invalid="ignore"):
        breaks = np.diff(ordered, axis=1) > np.maximum(_GAP_ABS, _GAP_REL * ordered[:, :-1])
    surface = np.zeros((n, p), dtype=np.int64)
    np.cumsum(breaks, axis=1, out=surface[:, 1:])
    valid = np.arange(p)[None, :] < count[:, None]
    sizes = np.bincount((rows[:, None] * p + surface)[valid], minlength=n * p).reshape(n, p)
    support = np.minimum(_MIN_SUPPORT, sizes.max(axis=1))
    chosen = np.argmax(sizes >= support[:, None], axis=1)
    start = np.argmax(surface == chosen[:, None], axis=1)
    size = sizes[rows, chosen]
    lo = np.minimum(start + np.maximum(size - 1, 0) // 2, p - 1)
    hi = np.minimum(start + size // 2, p - 1)
    mid = 0.5 * (ordered[rows, lo] + ordered[rows, hi])
    result[has] = mid[has]
    return result


def _patch_offsets(patch: int) -> tuple[np.ndarray, np.ndarray]:
    half = patch // 2
    dv, du = np.mgrid[-half : half + 1, -half : half + 1]
    return du.ravel(), dv.ravel()


def _check_pixels(pixels: np.ndarray, patch: int) -> np.ndarray:
    if isinstance(patch, bool) or not isinstance(patch, (int, np.integer)) or patch < 1 or patch % 2 == 0:
        raise ValueError(f"patch must be a positive odd integer (pixels), got {patch!r}")
    pixels = np.asarray(pixels, dtype=float)
    if pixels.size == 0:
        return pixels.reshape(0, 2)
    if pixels.ndim != 2 or pixels.shape[1] != 2:
        raise ValueError(f"pixels must be an (N, 2) array of (u, v) colour pixels, got shape {pixels.shape}")
    return pixels


def _registered_patches(depth_m: np.ndarray, pixels: np.ndarray, patch: int) -> np.ndarray:
    """(N, patch*patch) depths around each (rounded) pixel; NaN outside the image, at 0/NaN readings, at NaN pixels."""
    h, w = depth_m.shape
    finite = np.all(np.isfinite(pixels), axis=1)
    centre = np.floor(np.where(finite[:, None], pixels, -(10**6)) + 0.5).astype(np.int64)
    du, dv = _patch_offsets(patch)
    u = centre[:, :1] + du[None, :]
    v = centre[:, 1:] + dv[None, :]
    inside = (u >= 0) & (u < w) & (v >= 0) & (v < h)
    values = depth_m[np.clip(v, 0, h - 1), np.clip(u, 0, w - 1)].astype(float)
    with np.errstate(invalid="ignore"):
        values[~inside | ~(values > 0)] = np.nan
    return values


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
    x = (u_d - kd.cx) / kd.fx
    y = (v_d - kd.cy) / kd.fy
    # p_c = d * (R @ [x, y, 1]) + t, then K_c: homogeneous colour pixel = d * (K_c R ray) + K_c t.
    m = kc.K @ r
    b = kc.K @ t
    hx = d * (m[0, 0] * x + m[0, 1] * y + m[0, 2]) + b[0]
    hy = d * (m[1, 0] * x + m[1, 1] * y + m[1, 2]) + b[1]
    z = d * (m[2, 0] * x + m[2, 1] * y + m[2, 2]) + b[2]
    with np.errstate(divide="ignore", invalid="ignore"):
        return _Projection((hx / z).astype(dtype), (hy / z).astype(dtype), z.astype(dtype))


def _search_windows(
    pixels: np.ndarray, patch: int, calib: Calibration, depth_min: float, depth_max: float
) -> tuple[np.ndarray, np.ndarray, int, int]:
    """Per colour pixel, the depth-image window (u0, v0, width, height) that can land in its colour patch.

    The colour patch (a square of ``patch`` pixels, half a pixel beyond the outer centres) seen between depth_min and
    depth_max is a frustum; its image in the depth camera is the convex hull of its 8 projected corners (the
    epipolar band of the patch), so the window is that hull's bounding box plus one pixel for the splat corners.
    """
    assert calib.depth is not None
    kc, kd = calib.color, calib.depth
    r, t = calib.depth_to_color.rotation, calib.depth_to_color.translation
    half = patch // 2 + 0.5
    centre = np.floor(pixels + 0.5)
    corners = np.array([[-half, -half], [half, -half], [-half, half], [half, half]])
    uv = centre[:, None, :] + corners[None, :, :]  # (N, 4, 2)
    rays = np.stack([(uv[..., 0] - kc.cx) / kc.fx, (uv[..., 1] - kc.cy) / kc.fy, np.ones(uv.shape[:2])], axis=-1)
    points = np.concatenate([rays * depth_min, rays * depth_max], axis=1)  # (N, 8, 3) colour frame
    in_depth = (points - t) @ r  # R^T (p_c - t), row-vector form
    ud = in_depth[..., 0] / in_depth[..., 2] * kd.fx + kd.cx
    vd = in_depth[..., 1] / in_depth[..., 2] * kd.fy + kd.cy
    lo = np.floor(np.stack([ud.min(axis=1), vd.min(axis=1)], axis=1)) - 1
    hi = np.ceil(np.stack([ud.max(axis=1), vd.max(axis=1)], axis=1)) + 1
    lo = np.clip(lo, 0, [kd.width - 1, kd.height - 1]).astype(np.int64)
    hi = np.clip(hi, 0, [kd.width - 1, kd.height - 1]).astype(np.int64)
    size = hi - lo + 1
    return lo, hi, int(size[:, 0].max()), int(size[:, 1].max())


def _splat_cells(
    proj_lo: _Projection, proj_hi: _Projection | None
) -> tuple[list[np.ndarray], list[np.ndarray], list[np.ndarray]]:
    """Colour pixels each depth point writes: lists of (column, row, mask) arrays, one entry per rectangle offset.

    ``proj_hi`` None: point splat (the centre's pixel). Otherwise the inclusive rectangle between the rounded
    corners ``proj_lo`` (top-left) and ``proj_hi`` (bottom-right).
    """
    with np.errstate(invalid="ignore"):
        x0 = np.floor(proj_lo.u + 0.5)
        y0 = np.floor(proj_lo.v + 0.5)
        ok = np.isfinite(x0) & np.isfinite(y0) & (proj_lo.z > 0)
        if proj_hi is None:
            return [x0], [y0], [ok]
        x1 = np.floor(proj_hi.u + 0.5)
        y1 = np.floor(proj_hi.v + 0.5)
        ok &= np.isfinite(x1) & np.isfinite(y1) & (proj_hi.z > 0)
    span_x = np.where(ok, x1 - x0, -1)
    span_y = np.where(ok, y1 - y0, -1)
    cols, rows, masks = [], [], []
    for oy in range(int(max(span_y.max(initial=-1), -1)) + 1):
        for ox in range(int(max(span_x.max(initial=-1), -1)) + 1):
            cols.append(x0 + ox)
            rows.append(y0 + oy)
            masks.append((span_x >= ox) & (span_y >= oy))
    return cols, rows, masks


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
) -> np.ndarray:
    """Depth (metres, colour camera z) at colour pixels, robust to holes and silhouette edges.

    depth_m: the frame's depth (float metres, 0/NaN = no reading), registered to colour when ``calib.depth`` is
    None, else in the depth camera's grid. pixels: (N, 2) colour pixels (u, v); a NaN pixel gives NaN.
    Returns (N,) metres, NaN where the ``patch`` x ``patch`` window around the pixel holds no valid depth.

    Reduction (``method``): ``"nearest"`` (default) sorts the patch's readings, splits them into surfaces at depth
    jumps and returns the median of the nearest surface with at least 3 pixels: a keypoint on a person's silhouette
    keeps the person, not the wall behind, and one flying pixel or a noise spike does not decide. ``"min"`` is what
    the paper's authors did (minimum over 5x5), which follows single outliers; ``"median"`` mixes surfaces at edges.

    Unregistered depth is looked up sparsely, without aligning the frame: for each pixel, the depth pixels whose
    3D points can land in its colour patch lie in a small window around the patch's epipolar band between
    ``depth_min`` and ``depth_max`` (metres); only that window is mapped through the exact forward transform
    (same ``mode``/``value`` as ``Aligner``), z-buffered per colour pixel of the patch and reduced as above. The
    result equals aligning the whole frame and reading the patch, for readings within [depth_min, depth_max].
    """
    pixels = _check_pixels(pixels, patch)
    if calib.depth is None:
        depth_m = _validate_depth(depth_m, calib.color, "depth_at_color_pixels")
        if len(pixels) == 0:
            return np.zeros(0)
        return _reduce_patches(_registered_patches(depth_m, pixels, patch), method)
    depth_m = _validate_depth(depth_m, calib.depth, "depth_at_color_pixels")
    if not (0 < depth_min < depth_max and np.isfinite(depth_max)):
        raise ValueError(f"need 0 < depth_min < depth_max < inf, got {depth_min}, {depth_max}")
    if len(pixels) == 0:
        return np.zeros(0)
    return _reduce_patches(
        _unregistered_patches(depth_m, pixels, calib, patch, mode, value, depth_min, depth_max), method
    )


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
    if mode not in ("rectangle", "point"):
        raise ValueError(f"unknown splat mode {mode!r}; use 'rectangle' or 'point'")
    if value not in ("z", "depth"):
        raise ValueError(f"unknown stored value {value!r}; use 'z' or 'depth'")
    assert calib.depth is not None
    n = len(pixels)
    out = np.full((n, patch * patch), np.inf)
    finite = np.all(np.isfinite(pixels), axis=1)
    if not finite.any():
        return np.full((n, patch * patch), np.nan)
    idx = np.flatnonzero(finite)
    px = pixels[idx]
    lo, hi, ww, wh = _search_windows(px, patch, calib, depth_min, depth_max)
    gy, gx = np.mgrid[0:wh, 0:ww]
    u_d = lo[:, :1] + gx.ravel()[None, :]  # (n, M) depth pixel columns
    v_d = lo[:, 1:] + gy.ravel()[None, :]
    inside = (u_d <= hi[:, :1]) & (v_d <= hi[:, 1:])
    d = depth_m[np.minimum(v_d, calib.depth.height - 1), np.minimum(u_d, calib.depth.width - 1)].astype(float)
    with np.errstate(invalid="ignore"):
        inside &= (d >= depth_min) & (d <= depth_max)
    u_d, v_d, d = u_d[inside], v_d[inside], d[inside]
    owner = np.broadcast_to(np.arange(len(idx))[:, None], inside.shape)[inside]
    if mode == "point":
        centre = _project_depth_points(u_d, v_d, d, calib)
        cols, rows, masks = _splat_cells(centre, None)
    else:
        centre = _project_depth_points(u_d, v_d, d, calib) if value == "z" else None
        cols, rows, masks = _splat_cells(
            _project_depth_points(u_d - 0.5, v_d - 0.5, d, calib), _project_depth_points(u_d + 0.5, v_d + 0.5, d, calib)
        )
    stored = centre.z if value == "z" else d
    half = patch // 2
    centre_px = np.floor(px + 0.5)[owner]
    kc = calib.color
    for col, row, mask in zip(cols, rows, masks, strict=True):
        cu = col - centre_px[:, 0] + half
        cv = row - centre_px[:, 1] + half
        keep = mask & (cu >= 0) & (cu < patch) & (cv >= 0) & (cv < patch) & (col >= 0) & (col < kc.width)
        keep &= (row >= 0) & (row < kc.height)
        cell = (cv[keep] * patch + cu[keep]).astype(np.int64)
        np.minimum.at(out, (idx[owner[keep]], cell), stored[keep])
    out[~np.isfinite(out)] = np.nan
    return out
