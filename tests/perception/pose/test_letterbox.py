"""Letterbox arithmetic: image pixels <-> model-input pixels, exactly, in the pixel-centre convention."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from sid.perception.pose import multipose_input_size
from sid.perception.pose.base import Letterbox, clip_corners, fit_letterbox

sizes = st.tuples(st.integers(1, 2000), st.integers(1, 2000))


def _to_image(letterbox: Letterbox, uv: np.ndarray) -> np.ndarray:
    """Model-input pixels (..., 2) as (u, v) -> image pixels, through the decoders' inverse (normalised_to_image)."""
    in_h, in_w = letterbox.input_size
    return letterbox.normalised_to_image((np.asarray(uv, dtype=float) + 0.5) / (in_w, in_h))


@given(image=sizes, model=sizes, uv=st.lists(st.floats(-1e4, 1e4), min_size=2, max_size=2))
def test_fit_forward_then_inverse_is_identity(image, model, uv):
    letterbox = Letterbox.fit(image, model)
    point = np.array(uv)
    np.testing.assert_allclose(_to_image(letterbox, letterbox.to_input(point)), point, rtol=1e-9, atol=1e-6)


@given(
    box=st.tuples(st.floats(-100, 700), st.floats(-100, 500), st.floats(1, 400), st.floats(1, 400)),
    expand=st.floats(0.5, 2.0),
    uv=st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=2),
)
def test_crop_forward_then_inverse_is_identity(box, expand, uv):
    u0, v0, bw, bh = box
    letterbox = Letterbox.crop((u0, v0, u0 + bw, v0 + bh), (192, 192), expand)
    point = np.array(uv)
    np.testing.assert_allclose(_to_image(letterbox, letterbox.to_input(point)), point, rtol=1e-9, atol=1e-6)


def test_fit_640x480_into_256_square_puts_corners_on_the_padding_bands():
    letterbox = Letterbox.fit((480, 640), (256, 256))
    assert (letterbox.scale, letterbox.pad_x, letterbox.pad_y) == (0.4, 0.0, 32.0)
    # The image's outer corners (pixel-centre convention: -0.5 and size - 0.5) land on the band edges.
    np.testing.assert_allclose(letterbox.to_input([-0.5, -0.5]), [-0.5, 31.5])
    np.testing.assert_allclose(letterbox.to_input([639.5, 479.5]), [255.5, 223.5])
    # The centre of the top-left pixel is 0.2 input pixels inside that corner.
    np.testing.assert_allclose(letterbox.to_input([0.0, 0.0]), [-0.3, 31.7])
    # Normalised model outputs: (0, 0) is the input's top-left edge, here on the padding band above the image.
    np.testing.assert_allclose(letterbox.normalised_to_image([0.0, 32 / 256]), [-0.5, -0.5])
    np.testing.assert_allclose(letterbox.normalised_to_image([1.0, 224 / 256]), [639.5, 479.5])


def test_fit_portrait_pads_left_and_right():
    letterbox = Letterbox.fit((400, 200), (256, 256))
    assert (letterbox.scale, letterbox.pad_x, letterbox.pad_y) == (0.64, 64.0, 0.0)
    np.testing.assert_allclose(letterbox.to_input([-0.5, -0.5]), [63.5, -0.5])


def test_crop_centres_the_box_and_scales_its_long_side():
    letterbox = Letterbox.crop((100.0, 200.0, 140.0, 300.0), (192, 192), expand=1.2)
    assert letterbox.scale == pytest.approx(192 / 120)
    np.testing.assert_allclose(letterbox.normalised_to_image([0.5, 0.5]), [120.0, 250.0])
    # Square crop 1.2 x 100 = 120 px: the input's top edge is 60 px above the box centre.
    np.testing.assert_allclose(letterbox.normalised_to_image([0.5, 0.0]), [120.0, 190.0])


@pytest.mark.parametrize(
    "letterbox",
    [
        Letterbox.fit((480, 640), (256, 256)),
        Letterbox.fit((480, 640), (96, 128)),
        Letterbox.crop((300, 80, 380, 400), (192, 192)),
    ],
)
def test_warp_resamples_exactly_where_the_map_says(letterbox):
    """On linear ramps bilinear sampling is exact, so each input pixel holds the ramp at ``_to_image`` of it."""
    h, w = 480, 640
    v, u = np.mgrid[0:h, 0:w].astype(float)
    image = np.stack([u * 250 / (w - 1), v * 250 / (h - 1), np.zeros_like(u)], axis=-1).round().astype(np.uint8)
    warped = letterbox.warp(image, fill=0).astype(float)
    in_h, in_w = letterbox.input_size
    rows, cols = np.mgrid[0:in_h, 0:in_w]
    source = _to_image(letterbox, np.stack([cols, rows], axis=-1).astype(float))
    inside = (source[..., 0] >= 1) & (source[..., 0] <= w - 2) & (source[..., 1] >= 1) & (source[..., 1] <= h - 2)
    assert inside.sum() > 1000
    expected_u = source[..., 0] * 250 / (w - 1)
    expected_v = source[..., 1] * 250 / (h - 1)
    assert np.abs(warped[..., 0] - expected_u)[inside].max() <= 1.0
    assert np.abs(warped[..., 1] - expected_v)[inside].max() <= 1.0
    outside = (source[..., 0] < -1) | (source[..., 0] > w) | (source[..., 1] < -1) | (source[..., 1] > h)
    assert np.all(warped[outside] == 0)


@pytest.mark.parametrize(
    ("image_hw", "input_hw"), [((480, 640), (256, 256)), ((480, 640), (192, 320)), ((90, 60), (96, 64))]
)
def test_whole_pixel_letterbox_resizes_within_one_grey_level_of_warp_affine(image_hw, input_hw):
    """When the image fills whole input pixels, ``warp`` resizes and pads instead of ``cv2.warpAffine``: the same
    sampling positions, the padding bands exactly, the interpolated values within one grey level."""
    letterbox = Letterbox.fit(image_hw, input_hw)
    image = np.random.default_rng(0).integers(0, 256, (*image_hw, 3), dtype=np.uint8)
    image = cv2.GaussianBlur(image, (0, 0), 2.0)  # camera-like content, not pure noise
    in_h, in_w = input_hw
    reference = cv2.warpAffine(image, letterbox.matrix(), (in_w, in_h), flags=cv2.INTER_LINEAR,
                               borderMode=cv2.BORDER_CONSTANT, borderValue=(114, 114, 114))  # fmt: skip
    fast = letterbox.warp(image, 114)
    assert fast.shape == reference.shape and fast.dtype == np.uint8
    assert np.abs(fast.astype(int) - reference.astype(int)).max() <= 1
    top, left = int(letterbox.pad_y), int(letterbox.pad_x)
    assert np.all(fast[:top] == 114) and np.all(fast[:, :left] == 114)


@pytest.mark.parametrize(
    ("image_hw", "input_hw"), [((480, 640), (256, 256)), ((640, 480), (256, 256)), ((480, 640), (192, 320))]
)
def test_whole_pixel_warp_is_resize_then_border_bit_for_bit(image_hw, input_hw):
    """Resizing straight into the input and filling the bands (rows or columns) gives the pixels of a resize
    into its own array padded by ``cv2.copyMakeBorder``."""
    letterbox = Letterbox.fit(image_hw, input_hw)
    image = np.random.default_rng(1).integers(0, 256, (*image_hw, 3), dtype=np.uint8)
    (in_h, in_w), top, left = input_hw, int(letterbox.pad_y), int(letterbox.pad_x)
    width, height = round(image_hw[1] * letterbox.scale), round(image_hw[0] * letterbox.scale)
    resized = cv2.resize(image, (width, height), interpolation=cv2.INTER_LINEAR)
    expected = cv2.copyMakeBorder(resized, top, in_h - top - height, left, in_w - left - width,
                                  cv2.BORDER_CONSTANT, value=(7, 7, 7))  # fmt: skip
    np.testing.assert_array_equal(letterbox.warp(image, 7), expected)


def test_fit_letterbox_is_built_once_per_size_pair():
    first = fit_letterbox((480, 640), (256, 256))
    assert first is fit_letterbox((480, 640), (256, 256)) and first == Letterbox.fit((480, 640), (256, 256))
    assert fit_letterbox((720, 1280), (256, 256)) != first


def test_in_place_map_is_the_copying_map_and_corners_clip_to_the_outer_edge():
    letterbox = Letterbox.crop((100.0, 200.0, 140.0, 300.0), (192, 192))
    xy = np.random.default_rng(2).uniform(-0.5, 1.5, (3, 19, 2))
    expected = letterbox.normalised_to_image(xy)
    assert letterbox.normalised_to_image_in_place(xy) is xy
    np.testing.assert_array_equal(xy, expected)
    corners = np.array([[[-3.0, 5.0], [700.0, 500.0]], [[10.0, -1.0], [20.0, 479.0]]])
    clip_corners(corners, (480, 640))
    np.testing.assert_array_equal(corners, [[[-0.5, 5.0], [639.5, 479.5]], [[10.0, -0.5], [20.0, 479.0]]])


def test_bad_letterbox_arguments_are_named():
    with pytest.raises(ValueError, match="scale"):
        Letterbox(0.0, 0.0, 0.0, (10, 10))
    with pytest.raises(ValueError, match="u_max > u_min"):
        Letterbox.crop((10, 10, 5, 20), (192, 192))
    with pytest.raises(ValueError, match="finite"):
        Letterbox.crop((np.nan, 10, 50, 20), (192, 192))
    with pytest.raises(ValueError, match="image size"):
        Letterbox.fit((0, 640), (256, 256))


@pytest.mark.parametrize(
    ("image_hw", "size", "expected"),
    [
        ((480, 640), 256, (192, 256)),
        ((720, 1280), 256, (160, 256)),
        ((480, 640), "paper", (96, 128)),
        ((720, 1280), "paper", (96, 128)),
        ((640, 480), 256, (256, 192)),
        ((480, 640), (256, 256), (256, 256)),
    ],
)
def test_multipose_input_size(image_hw, size, expected):
    assert multipose_input_size(image_hw, size) == expected


@pytest.mark.parametrize("size", [100, 0, "huge", (250, 256)])
def test_multipose_input_size_rejects_sizes_that_are_not_multiples_of_32(size):
    with pytest.raises(ValueError, match="multiple|paper"):
        multipose_input_size((480, 640), size)
