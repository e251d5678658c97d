"""Depth-to-colour alignment and sparse keypoint depth, checked against a per-pixel reference implementation."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from sid.perception.align import Aligner, align_depth_to_color, depth_at_color_pixels
from sid.perception.camera import Calibration, Extrinsics, Intrinsics, deproject, project

DEPTH = Intrinsics(48, 36, 40.0, 41.0, 23.2, 17.6)
COLOR = Intrinsics(80, 60, 60.0, 60.5, 39.7, 29.1)
ROTATION = Rotation.from_euler("xyz", [1.5, -2.0, 1.0], degrees=True).as_matrix()
CALIB = Calibration(COLOR, DEPTH, Extrinsics(ROTATION, [0.04, -0.01, 0.005]))


def scene(shape: tuple[int, int] = (DEPTH.height, DEPTH.width), seed: int = 0) -> np.ndarray:
    """A wall at 3 m, a box at 1.2 m in front of it, noise and holes (0 and NaN)."""
    rng = np.random.default_rng(seed)
    h, w = shape
    depth = np.full(shape, 3.0) + rng.normal(0, 0.01, shape)
    box = (slice(h // 4, 3 * h // 4), slice(w // 3, 2 * w // 3))
    depth[box] = 1.2 + rng.normal(0, 0.005, depth[box].shape)
    depth[rng.random(shape) < 0.05] = 0.0
    depth[rng.random(shape) < 0.02] = np.nan
    return depth.astype(np.float32)


def reference_align(depth: np.ndarray, calib: Calibration, mode: str, value: str) -> np.ndarray:
    """One depth pixel at a time, written from the module docstring (librealsense's loop for rectangles)."""
    kd, kc, ext = calib.depth, calib.color, calib.depth_to_color
    out = np.full((kc.height, kc.width), np.inf)

    def to_color(u: float, v: float, d: float) -> tuple[float, float, float]:
        p = ext.rotation @ np.array([(u - kd.cx) / kd.fx * d, (v - kd.cy) / kd.fy * d, d]) + ext.translation
        return p[0] / p[2] * kc.fx + kc.cx, p[1] / p[2] * kc.fy + kc.cy, p[2]

    for v in range(kd.height):
        for u in range(kd.width):
            d = float(depth[v, u])
            if not d > 0:
                continue
            uc, vc, zc = to_color(u, v, d)
            stored = zc if value == "z" else d
            if mode == "point":
                corners = [(uc, vc), (uc, vc)]
            else:
                corners = [to_color(u - 0.5, v - 0.5, d)[:2], to_color(u + 0.5, v + 0.5, d)[:2]]
            (x0, y0), (x1, y1) = [(math.floor(a + 0.5), math.floor(b + 0.5)) for a, b in corners]
            for row in range(max(y0, 0), min(y1, kc.height - 1) + 1):
                for col in range(max(x0, 0), min(x1, kc.width - 1) + 1):
                    out[row, col] = min(out[row, col], stored)
    out[np.isinf(out)] = 0
    return out


@pytest.mark.parametrize("mode", ["rectangle", "point"])
@pytest.mark.parametrize("value", ["z", "depth"])
def test_alignment_matches_per_pixel_reference(mode: str, value: str) -> None:
    depth = scene()
    ours = Aligner(CALIB, mode, value)(depth)
    expected = reference_align(depth, CALIB, mode, value)
    assert ours.shape == (COLOR.height, COLOR.width) and ours.dtype == np.float32
    assert np.array_equal(ours > 0, expected > 0)
    np.testing.assert_allclose(ours, expected, atol=2e-6, rtol=1e-6)


def test_rectangle_splat_is_dense_and_point_splat_leaves_holes_when_upsampling() -> None:
    depth = np.full((DEPTH.height, DEPTH.width), 2.0, np.float32)
    dense = align_depth_to_color(depth, CALIB, mode="rectangle")
    sparse = align_depth_to_color(depth, CALIB, mode="point")
    inner = (slice(10, -10), slice(10, -10))
    assert np.all(dense[inner] > 0)
    assert 0.2 < np.mean(sparse[inner] > 0) < 0.7  # ~ (40/60)^2 of the colour pixels get a depth pixel


def test_nearest_wins_at_occlusions() -> None:
    # A thin near bar in front of a far wall: the colour pixels where both land must keep the bar.
    depth = np.full((DEPTH.height, DEPTH.width), 4.0, np.float32)
    depth[:, 20:23] = 1.0
    for mode in ("rectangle", "point"):
        aligned = align_depth_to_color(depth, CALIB, mode=mode)
        expected = reference_align(depth, CALIB, mode, "z")
        np.testing.assert_allclose(aligned, expected, atol=2e-6)
        assert np.count_nonzero(np.isclose(aligned, 1.0, atol=0.05)) > 0


def test_stored_value_z_is_the_colour_frame_depth() -> None:
    # Pure translation along z: colour-frame z = depth + t_z everywhere.
    calib = Calibration(COLOR, DEPTH, Extrinsics(np.eye(3), [0.0, 0.0, 0.1]))
    depth = np.full((DEPTH.height, DEPTH.width), 2.0, np.float32)
    z = align_depth_to_color(depth, calib, value="z")
    raw = align_depth_to_color(depth, calib, value="depth")
    np.testing.assert_allclose(z[z > 0], 2.1, atol=1e-6)
    np.testing.assert_allclose(raw[raw > 0], 2.0, atol=1e-6)


def test_identity_geometry_point_splat_is_the_identity_and_rectangles_overlap_by_one_pixel() -> None:
    intr = Intrinsics(32, 24, 30.0, 30.0, 15.5, 11.5)
    depth = scene((24, 32), seed=3)
    clean = np.nan_to_num(depth, nan=0.0)
    point = align_depth_to_color(depth, Calibration(intr, intr), mode="point")
    np.testing.assert_allclose(point, clean, atol=1e-6)
    # librealsense's rounding: pixel (u, v) has corners at u +- 0.5, exactly between two colour pixels; float
    # rounding picks a side, so a depth pixel writes 1 to 2 pixels per axis and colour pixel (r, c) holds the nearest
    # of some of its 3x3 neighbours, itself included when valid.
    rect = align_depth_to_color(depth, Calibration(intr, intr), mode="rectangle")
    padded = np.pad(np.where(clean > 0, clean, np.inf), 1, constant_values=np.inf)
    window = np.min([padded[1 + dy : 25 + dy, 1 + dx : 33 + dx] for dy in (-1, 0, 1) for dx in (-1, 0, 1)], axis=0)
    own = clean > 0
    assert np.all(rect[own] <= clean[own]) and np.all(rect[own] >= window[own])
    assert np.mean(rect[own] < clean[own]) > 0.1  # the overlap is real, not an edge case


def test_empty_and_bad_inputs() -> None:
    aligner = Aligner(CALIB)
    assert not aligner(np.zeros((DEPTH.height, DEPTH.width), np.float32)).any()
    assert not aligner(np.full((DEPTH.height, DEPTH.width), np.nan, np.float32)).any()
    with pytest.raises(ValueError, match="48x36"):
        aligner(np.zeros((10, 10), np.float32))
    with pytest.raises(ValueError, match="float metres"):
        aligner(np.zeros((DEPTH.height, DEPTH.width), np.uint16))
    with pytest.raises(ValueError, match="splat mode"):
        Aligner(CALIB, mode="splat")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="no depth intrinsics"):
        Aligner(Calibration(COLOR))
    registered = np.full((COLOR.height, COLOR.width), np.nan, np.float32)
    assert not align_depth_to_color(registered, Calibration(COLOR)).any()


# --- sparse keypoint depth -------------------------------------------------------------------------------------


def test_registered_patch_lookup_ignores_holes_and_keeps_the_person_at_edges() -> None:
    calib = Calibration(COLOR)
    depth = np.full((COLOR.height, COLOR.width), 4.0, np.float32)
    depth[:, :40] = 2.0  # a person on the left, a wall at 4 m on the right
    depth[10:13, 10:13] = 0.0
    depth[30, 5] = np.nan
    pixels = np.array([[39.0, 20.0], [40.0, 20.0], [41.0, 20.0], [11.0, 11.0], [5.0, 30.0], [60.0, 30.0]])
    got = depth_at_color_pixels(depth, pixels, calib)
    np.testing.assert_allclose(got, [2.0, 2.0, 2.0, 2.0, 2.0, 4.0])
    # The plain median would pick the wall on the edge pixel that has more wall than person in its patch.
    assert depth_at_color_pixels(depth, pixels[2:3], calib, method="median")[0] == 4.0


def test_no_valid_depth_gives_nan_never_zero() -> None:
    calib = Calibration(COLOR)
    depth = np.zeros((COLOR.height, COLOR.width), np.float32)
    depth[0, 0] = 1.0
    pixels = np.array([[40.0, 30.0], [np.nan, 3.0], [-50.0, 10.0], [1.0, 1.0]])
    got = depth_at_color_pixels(depth, pixels, calib)
    assert np.isnan(got[:3]).all() and got[3] == 1.0
    assert depth_at_color_pixels(depth, np.zeros((0, 2)), calib).shape == (0,)


def test_nearest_surface_needs_support_so_a_single_flying_pixel_does_not_decide() -> None:
    calib = Calibration(COLOR)
    depth = np.full((COLOR.height, COLOR.width), 3.0, np.float32)
    depth[20, 20] = 0.5  # one outlier in the 5x5 patch
    assert depth_at_color_pixels(depth, np.array([[20.0, 20.0]]), calib)[0] == 3.0
    assert depth_at_color_pixels(depth, np.array([[20.0, 20.0]]), calib, method="min")[0] == 0.5


def reference_nearest(readings: np.ndarray, min_support: int = 3) -> float:
    """The "nearest" reduction of one patch, one sorted reading at a time (``depth_at_color_pixels``' docstring)."""
    values = sorted(float(x) for x in readings if x > 0)
    if not values:
        return math.nan
    surfaces = [[values[0]]]
    for before, after in zip(values[:-1], values[1:], strict=True):
        if after - before > max(0.10, 0.05 * before):
            surfaces.append([])
        surfaces[-1].append(after)
    support = min(min_support, max(map(len, surfaces)))
    chosen = next(surface for surface in surfaces if len(surface) >= support)
    return 0.5 * (chosen[(len(chosen) - 1) // 2] + chosen[len(chosen) // 2])


def test_nearest_surface_of_patches_with_several_surfaces_matches_a_reading_by_reading_reference() -> None:
    """Patches of 1-4 surfaces of 0-25 readings each (single flying pixels, ties for the largest, holes)."""
    rng = np.random.default_rng(11)
    calib = Calibration(COLOR)
    depth = np.zeros((COLOR.height, COLOR.width), np.float32)
    pixels = np.array([[u, v] for v in range(2, COLOR.height - 2, 5) for u in range(2, COLOR.width - 2, 5)], float)
    for u, v in pixels.astype(int):
        levels = rng.choice([0.6, 1.0, 1.5, 2.2, 3.0, 4.5], size=rng.integers(1, 5), replace=False)
        patch = rng.choice(levels, size=(5, 5)) + rng.normal(0, rng.choice([0.0, 0.01]), (5, 5))
        patch[rng.random((5, 5)) < rng.uniform(0, 0.9)] = rng.choice([0.0, np.nan])
        depth[v - 2 : v + 3, u - 2 : u + 3] = patch
    got = depth_at_color_pixels(depth, pixels, calib)
    expected = [reference_nearest(depth[v - 2 : v + 3, u - 2 : u + 3].ravel()) for u, v in pixels.astype(int)]
    np.testing.assert_array_equal(got, expected)
    assert np.isnan(got).sum() < len(got) // 4


def test_an_infinite_reading_is_no_reading() -> None:
    rng = np.random.default_rng(12)
    depth = scene((COLOR.height, COLOR.width), seed=3)
    holes = rng.random(depth.shape) < 0.3
    pixels = np.column_stack([rng.uniform(-2, COLOR.width + 1, 200), rng.uniform(-2, COLOR.height + 1, 200)])
    for method in ("nearest", "min", "median"):
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no inf - inf on the way
            got = depth_at_color_pixels(np.where(holes, np.inf, depth), pixels, Calibration(COLOR), method=method)
        expected = depth_at_color_pixels(np.where(holes, 0.0, depth), pixels, Calibration(COLOR), method=method)
        np.testing.assert_array_equal(got, expected)


def test_bad_arguments_are_named() -> None:
    calib = Calibration(COLOR)
    depth = np.ones((COLOR.height, COLOR.width), np.float32)
    with pytest.raises(ValueError, match="odd"):
        depth_at_color_pixels(depth, np.zeros((1, 2)), calib, patch=4)
    with pytest.raises(ValueError, match=r"\(N, 2\)"):
        depth_at_color_pixels(depth, np.zeros((3, 3)), calib)
    with pytest.raises(ValueError, match="patch method"):
        depth_at_color_pixels(depth, np.zeros((1, 2)), calib, method="mean")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="80x60"):
        depth_at_color_pixels(np.ones((5, 5), np.float32), np.zeros((1, 2)), calib)


@pytest.mark.parametrize("mode", ["rectangle", "point"])
@pytest.mark.parametrize("method", ["nearest", "min", "median"])
def test_sparse_unregistered_lookup_equals_full_alignment_then_lookup(mode: str, method: str) -> None:
    depth = scene(seed=7)
    aligned = align_depth_to_color(depth, CALIB, mode=mode)
    rng = np.random.default_rng(1)
    pixels = np.column_stack([rng.uniform(-3, COLOR.width + 3, 200), rng.uniform(-3, COLOR.height + 3, 200)])
    pixels[7] = np.nan  # a dropped keypoint
    registered = Calibration(COLOR)
    for patch in (1, 3, 5):
        sparse = depth_at_color_pixels(depth, pixels, CALIB, patch, method=method, mode=mode)
        dense = depth_at_color_pixels(aligned, pixels, registered, patch, method=method)
        np.testing.assert_allclose(sparse, dense, atol=2e-6, equal_nan=True)
    assert np.isfinite(sparse).sum() > 150 and np.isnan(sparse[7])


def test_sparse_lookup_on_a_realistic_d435i_pair() -> None:
    depth_intr = Intrinsics(848, 480, 426.0, 426.0, 423.5, 239.8)
    color_intr = Intrinsics(1280, 720, 910.0, 910.0, 641.2, 358.9)
    calib = Calibration(color_intr, depth_intr, Extrinsics(ROTATION, [0.015, 0.0003, 0.0002]))
    depth = np.full((480, 848), 3.5, np.float32)
    depth[150:400, 380:470] = 1.8  # a person
    rng = np.random.default_rng(2)
    pixels = np.column_stack([rng.uniform(0, 1280, 68), rng.uniform(0, 720, 68)])
    dense = depth_at_color_pixels(align_depth_to_color(depth, calib), pixels, Calibration(color_intr))
    np.testing.assert_allclose(depth_at_color_pixels(depth, pixels, calib), dense, atol=2e-6, equal_nan=True)


def test_window_search_stays_close_to_the_full_alignment_on_a_d435i_pair() -> None:
    """``search="window"`` (the lift's default) against aligning the whole frame: on flat surfaces at 1.8 m and
    3.5 m, keypoints away from the silhouette get the surface's colour-frame depth within a centimetre, and at most a
    few keypoints next to the silhouette read the other surface."""
    depth_intr = Intrinsics(848, 480, 426.0, 426.0, 423.5, 239.8)
    color_intr = Intrinsics(1280, 720, 910.0, 910.0, 641.2, 358.9)
    calib = Calibration(color_intr, depth_intr, Extrinsics(ROTATION, [0.015, 0.0003, 0.0002]))
    rng = np.random.default_rng(3)
    depth = (np.full((480, 848), 3.5) + rng.normal(0, 0.005, (480, 848))).astype(np.float32)
    depth[150:400, 380:470] = 1.8 + rng.normal(0, 0.003, (250, 90))  # a person
    depth[rng.random(depth.shape) < 0.02] = 0.0  # holes
    pixels = np.column_stack([rng.uniform(0, 1280, 400), rng.uniform(0, 720, 400)])
    pixels[5] = np.nan
    dense = depth_at_color_pixels(align_depth_to_color(depth, calib), pixels, Calibration(color_intr))
    window = depth_at_color_pixels(depth, pixels, calib, search="window")
    assert np.isnan(window[5])
    both = np.isfinite(dense) & np.isfinite(window)
    assert both.sum() > 350
    error = np.abs(window - dense)[both]
    assert np.median(error) < 0.01
    assert np.count_nonzero(error > 0.05) <= 8  # silhouette keypoints: 1.8 m against 3.5 m
    # A keypoint well inside the person reads the person, one well outside the wall (colour-frame z, as dense).
    person_u = (425.0 - depth_intr.cx) / depth_intr.fx * color_intr.fx + color_intr.cx  # the person's centre column
    two = np.array([[person_u, 500.0], [200.0, 100.0]])
    dense_two = depth_at_color_pixels(align_depth_to_color(depth, calib), two, Calibration(color_intr))
    assert abs(dense_two[0] - 1.8) < 0.05 and abs(dense_two[1] - 3.5) < 0.1  # the person, the wall
    np.testing.assert_allclose(depth_at_color_pixels(depth, two, calib, search="window"), dense_two, atol=0.01)


def test_window_search_reads_each_pixel_alone_whatever_the_others_and_the_calibrations_before() -> None:
    """The window search has a fast path (every window inside the depth image) and keeps per-calibration tables; a
    pixel's depth must not depend on either: the same with pixels near the border in the call or alone, and right
    (near the full alignment, as above) for each of more calibrations than it keeps, one after the other."""
    depth = scene(seed=4)
    rng = np.random.default_rng(6)
    inner = np.column_stack([rng.uniform(25, 55, 40), rng.uniform(20, 40, 40)])
    border = np.array([[0.0, 0.0], [79.4, 30.0], [40.0, 59.6], [-2.0, 10.0], [np.nan, 5.0]])
    for patch in (1, 3, 5):
        alone = depth_at_color_pixels(depth, inner, CALIB, patch, search="window")
        mixed = depth_at_color_pixels(depth, np.concatenate([inner, border]), CALIB, patch, search="window")
        np.testing.assert_array_equal(mixed[: len(inner)], alone)
        assert np.isfinite(alone).sum() > 35 and np.isnan(mixed[-1])
    first = depth_at_color_pixels(depth, inner, CALIB, search="window")
    pixels = np.column_stack([rng.uniform(0, COLOR.width, 300), rng.uniform(0, COLOR.height, 300)])
    for k in range(1, 7):  # a table left from another calibration is off by 3-10 cm here
        turned = Rotation.from_euler("xyz", [1.5 + 2 * k, -2.0 - 2 * k, 1.0], degrees=True).as_matrix()
        calib = Calibration(COLOR, DEPTH, Extrinsics(turned, [0.04, -0.01, 0.005]))
        dense = depth_at_color_pixels(align_depth_to_color(depth, calib), pixels, Calibration(COLOR))
        window = depth_at_color_pixels(depth, pixels, calib, search="window")
        assert np.nanmedian(np.abs(window - dense)) < 0.015
    again = Calibration(COLOR, DEPTH, Extrinsics(ROTATION, [0.04, -0.01, 0.005]))
    np.testing.assert_array_equal(depth_at_color_pixels(depth, inner, again, search="window"), first)


def test_window_search_compares_float32_readings_with_the_range_in_float64() -> None:
    """A float32 reading is compared with depth_min and depth_max as it is (float32(0.3) is above 0.3), not with
    the range rounded to float32."""
    depth = np.full((DEPTH.height, DEPTH.width), np.float32(0.3))
    pixel = np.array([[40.0, 30.0]])
    assert np.isnan(depth_at_color_pixels(depth, pixel, CALIB, depth_min=0.1, depth_max=0.3, search="window"))[0]
    inside = depth_at_color_pixels(depth, pixel, CALIB, depth_min=0.1, depth_max=0.31, search="window")
    assert inside[0] == pytest.approx(0.3, abs=0.01)


def test_window_search_is_checked_by_name() -> None:
    with pytest.raises(ValueError, match="unknown depth search 'fast'"):
        depth_at_color_pixels(scene(seed=1), np.zeros((1, 2)), CALIB, search="fast")  # type: ignore[arg-type]


def test_registered_lookups_check_their_options_and_apply_the_depth_range():
    """The registered path ignored mode, value, depth_min and depth_max (a typo passed, a far wall decided)."""
    depth = np.zeros((COLOR.height, COLOR.width), np.float32)
    depth[28:33, 38:43] = 8.0  # a wall behind ...
    depth[30, 39:41] = 3.0  # ... two readings of someone in front: too few to be a surface on their own
    pixel = np.array([[40.0, 30.0]])
    assert depth_at_color_pixels(depth, pixel, Calibration(COLOR))[0] == 8.0
    assert depth_at_color_pixels(depth, pixel, Calibration(COLOR), depth_max=6.0)[0] == 3.0
    assert np.isnan(depth_at_color_pixels(depth, pixel, Calibration(COLOR), depth_min=3.5, depth_max=6.0)[0])
    for option, match in [
        ({"mode": "points"}, "unknown splat mode 'points'"),
        ({"value": "Z"}, "unknown stored value 'Z'"),
        ({"depth_min": 0.0}, "need 0 < depth_min < depth_max"),
        ({"depth_max": math.inf}, "need 0 < depth_min < depth_max"),
    ]:
        with pytest.raises(ValueError, match=match):
            depth_at_color_pixels(depth, pixel, Calibration(COLOR), **option)


@pytest.mark.parametrize("mode", ["point", "rectangle"])
def test_alignment_places_pixels_exactly_in_images_above_2_to_the_24_pixels(mode):
    """Flat colour-pixel indices were float32, which holds integers exactly only up to 2^24 (16.8 M): in the lower
    part of a 6144 x 3456 image (21.2 M pixels, within the image-size limit) pixels landed up to a column off."""
    color = Intrinsics(6144, 3456, 4800.0, 4800.0, 3071.5, 1727.5)
    depth_intr = Intrinsics(64, 36, 50.3, 50.2, 31.3, 17.7)  # one depth pixel covers ~96 x 96 colour pixels
    depth = np.zeros((depth_intr.height, depth_intr.width), np.float32)
    depth[1::3, 1::3] = 2.0  # sparse: each rectangle's edges show, not hidden under its neighbours'
    aligned = Aligner(Calibration(color, depth_intr), mode)(depth)
    v, u = np.nonzero(depth)
    expected = np.zeros(aligned.shape, bool)
    shifts = [0.0] if mode == "point" else [-0.5, 0.5]  # pixel centre, or the rectangle's two corners
    corners = [project(deproject(np.stack([u + s, v + s], 1), np.full(u.size, 2.0), depth_intr), color) for s in shifts]
    lo, hi = (np.floor(c + 0.5).astype(int) for c in (corners[0], corners[-1]))
    for (u0, v0), (u1, v1) in zip(lo, hi, strict=True):
        expected[max(v0, 0) : v1 + 1, max(u0, 0) : u1 + 1] = True
    np.testing.assert_array_equal(aligned > 0, expected)
    assert (aligned[expected] == 2.0).all()
