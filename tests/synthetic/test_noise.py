"""D435-like depth noise and keypoint noise of the synthetic source."""

from __future__ import annotations

import numpy as np
import pytest

from sid.synthetic.noise import DepthNoise, KeypointNoise, visible_to_right_imager

FOCAL = 420.0  # px, D435 depth at 848x480


def _quiet(**options: float | bool) -> DepthNoise:
    """Noise only (no holes, no shadow), with ``options`` changed."""
    base = {"hole_fraction": 0.0, "edge_holes": 0.0, "stereo_shadow": False}
    return DepthNoise(**{**base, **options})


def test_rms_follows_intels_formula() -> None:
    noise = DepthNoise()
    # z^2 * subpixel / (focal * baseline) = 4 * 0.08 / (420 * 0.05) at 2 m: 15.2 mm, 0.76 % of the distance.
    assert noise.rms(2.0, FOCAL) == pytest.approx(0.0152381, rel=1e-5)
    assert noise.rms(1.0, FOCAL) == pytest.approx(noise.rms(2.0, FOCAL) / 4)
    assert DepthNoise(focal_px=600.0).rms(2.0, FOCAL) == pytest.approx(4 * 0.08 / (600 * 0.05))


@pytest.mark.parametrize("correlation_px", [0.0, 2.0])
def test_measured_rms_at_2m_matches_the_model(correlation_px: float) -> None:
    noise = _quiet(correlation_px=correlation_px)
    exact = np.full((480, 848), 2.0, dtype=np.float32)
    noisy = noise.apply(exact, FOCAL, np.random.default_rng(0))
    error = noisy.astype(np.float64) - 2.0
    # 407k samples: independent pixels estimate the RMS within ~0.1 %; correlated ones (~50 px per independent
    # blob) within ~1 %; 1 mm quantisation adds 0.29 mm in quadrature (0.02 %).
    tolerance = 0.01 if correlation_px == 0 else 0.05
    assert np.sqrt(np.mean(error**2)) == pytest.approx(noise.rms(2.0, FOCAL), rel=tolerance)
    assert abs(error.mean()) < 0.1 * noise.rms(2.0, FOCAL)
    neighbours = np.corrcoef(error[:, :-1].ravel(), error[:, 1:].ravel())[0, 1]
    if correlation_px == 0:
        assert abs(neighbours) < 0.01
    else:
        assert neighbours > 0.8


def test_depth_is_quantised_to_the_depth_unit_and_float32() -> None:
    noisy = _quiet().apply(np.full((50, 60), 1.5, dtype=np.float32), FOCAL, np.random.default_rng(1))
    assert noisy.dtype == np.float32
    millimetres = noisy.astype(np.float64) * 1000
    np.testing.assert_allclose(millimetres, np.round(millimetres), atol=1e-3)


def test_random_holes_and_range_limits() -> None:
    rng = np.random.default_rng(2)
    exact = np.full((200, 300), 3.0, dtype=np.float32)
    holes = _quiet(hole_fraction=0.1).apply(exact, FOCAL, rng)
    assert np.mean(holes == 0) == pytest.approx(0.1, abs=0.01)
    exact[:, :100] = 30.0  # beyond max range (even with the 4.3 m RMS noise at 30 m)
    exact[:, 100:200] = 0.2  # nearer than the minimum distance
    exact[:10, 200:] = 0.0  # nothing there
    out = _quiet().apply(exact, FOCAL, rng)
    assert np.all(out[:, :200] == 0) and np.all(out[:10, 200:] == 0)
    assert np.all(out[10:, 200:] > 0)


def test_stereo_shadow_left_of_a_near_object() -> None:
    depth = np.full((4, 200), 4.0)
    depth[:, 100:] = 1.0
    visible = visible_to_right_imager(depth, FOCAL * 0.05)
    # Background (4 m) pixels hidden left of the edge: f B (1/1 - 1/4) = 15.75 px.
    hidden_band = np.flatnonzero(~visible[0, :100])
    left_edge = hidden_band[hidden_band < 50]
    shadow = hidden_band[hidden_band >= 50]
    # A 4 m pixel u lands at u - 5.25 in the right image, the near edge (u = 100) at 100 - 21 = 79: hidden from 85.
    np.testing.assert_array_equal(shadow, np.arange(85, 100))
    # The left image border: pixels whose match would fall off the right image (f B / 4 = 5.25 px).
    assert len(left_edge) == 5
    assert np.all(visible[:, 100:])

    noisy = DepthNoise(hole_fraction=0, edge_holes=0).apply(depth.astype(np.float32), FOCAL, np.random.default_rng(0))
    assert np.all(noisy[:, 85:100] == 0) and np.all(noisy[:, 100:] > 0)


def test_edge_holes_only_near_depth_jumps() -> None:
    depth = np.full((60, 80), 3.0, dtype=np.float32)
    depth[20:40, 30:50] = 1.5
    noise = _quiet(subpixel=0.0, edge_holes=1.0, edge_width_px=2)
    out = noise.apply(depth, FOCAL, np.random.default_rng(3))
    holes = out == 0
    assert holes[20:40, 28:32].all() and holes[18:22, 30:50].all()
    assert not holes[:15].any() and not holes[25:35, 35:45].any()


def test_exact_noise_changes_nothing_and_seeds_reproduce() -> None:
    exact = np.random.default_rng(4).uniform(0.5, 6.0, (30, 40)).astype(np.float32)
    np.testing.assert_array_equal(DepthNoise.exact().apply(exact, FOCAL, np.random.default_rng(0)), exact)
    first = DepthNoise().apply(exact, FOCAL, np.random.default_rng(7))
    again = DepthNoise().apply(exact, FOCAL, np.random.default_rng(7))
    other = DepthNoise().apply(exact, FOCAL, np.random.default_rng(8))
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(first, other)


def test_keypoint_noise_sigma_and_drop_rate() -> None:
    pixels = np.zeros((20000, 2))
    noisy, kept = KeypointNoise(sigma_px=3.0, drop=0.25).apply(pixels, np.random.default_rng(5))
    assert noisy.std() == pytest.approx(3.0, rel=0.02)
    assert np.mean(~kept) == pytest.approx(0.25, abs=0.01)
    exact, all_kept = KeypointNoise(0.0, 0.0).apply(pixels, np.random.default_rng(5))
    np.testing.assert_array_equal(exact, pixels)
    assert all_kept.all()


@pytest.mark.parametrize(
    "options",
    [{"subpixel": -0.1}, {"baseline_m": 0.0}, {"hole_fraction": 1.5}, {"max_range_m": 0.1}, {"edge_width_px": -1},
     {"subpixel": float("nan")}, {"focal_px": 0.0}],
)  # fmt: skip
def test_bad_noise_parameters_are_rejected(options: dict[str, float]) -> None:
    with pytest.raises(ValueError, match="noise"):
        DepthNoise(**options)


@pytest.mark.parametrize("width", [0, 2.5, True, "2"])
def test_edge_width_must_be_a_whole_number_of_pixels_from_one(width: object) -> None:
    """0 acted as 1 and 2.5 failed later in the dilation with a TypeError."""
    with pytest.raises(ValueError, match="depth noise: edge_width_px must be a whole number >= 1"):
        DepthNoise(edge_width_px=width)  # type: ignore[arg-type]


def test_bad_keypoint_noise_is_rejected() -> None:
    with pytest.raises(ValueError, match="sigma_px"):
        KeypointNoise(sigma_px=-1.0)
    with pytest.raises(ValueError, match="drop"):
        KeypointNoise(drop=2.0)
