"""The small-N DBSCAN gives scikit-learn's labels exactly."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from sklearn.cluster import DBSCAN

from sid.perception.cluster import SMALL_N_MAX, _dbscan_dense, dbscan_labels


def sklearn_labels(points: np.ndarray, eps: float, min_samples: int) -> np.ndarray:
    return DBSCAN(eps=eps, min_samples=min_samples).fit_predict(points)


# Coordinates on a 0.25 m grid with eps a multiple of 0.25: every squared distance is exact in floating point, so
# duplicates and ties at exactly eps are frequent and both implementations see the same comparisons.
grid_points = st.integers(1, 40).flatmap(
    lambda n: st.lists(st.tuples(st.integers(-12, 12), st.integers(-12, 12)), min_size=n, max_size=n)
)


@settings(max_examples=400, deadline=None)
@given(grid_points, st.integers(1, 8), st.integers(1, 5))
def test_same_labels_as_sklearn_on_a_grid_with_ties_and_duplicates(cells, eps_quarters, min_samples):
    points = np.array(cells, dtype=float) * 0.25
    eps = eps_quarters * 0.25
    np.testing.assert_array_equal(_dbscan_dense(points, eps, min_samples), sklearn_labels(points, eps, min_samples))


@settings(max_examples=300, deadline=None)
@given(
    st.integers(1, 30).flatmap(
        lambda n: st.lists(
            st.tuples(st.floats(-10, 10, allow_nan=False), st.floats(-10, 10, allow_nan=False)),
            min_size=n,
            max_size=n,
        )
    ),
    st.floats(0.05, 5.0),
    st.integers(1, 6),
)
def test_same_labels_as_sklearn_on_random_points(coords, eps, min_samples):
    points = np.array(coords, dtype=float)
    # A squared distance within rounding error of eps^2 has no single right answer (see the next test): skip it.
    d2 = ((points[:, None, :] - points[None, :, :]) ** 2).sum(axis=-1)
    assume(np.min(np.abs(d2 - eps * eps)) > 1e-9)
    np.testing.assert_array_equal(_dbscan_dense(points, eps, min_samples), sklearn_labels(points, eps, min_samples))


def test_a_distance_within_rounding_of_eps_follows_exact_arithmetic_like_sklearns_kd_tree():
    # 0.05^2 == 0.05^2 in floating point, but scikit-learn's brute-force back-end (used below ~12 points) computes
    # |a|^2 - 2 a.b + |b|^2, which rounds above eps^2 here: its own back-ends disagree on this input.
    points = np.array([[2.0, 0.0], [2.0, 0.05]])
    brute = DBSCAN(eps=0.05, min_samples=1, algorithm="brute").fit_predict(points)
    kd_tree = DBSCAN(eps=0.05, min_samples=1, algorithm="kd_tree").fit_predict(points)
    assert brute.tolist() == [0, 1] and kd_tree.tolist() == [0, 0]
    np.testing.assert_array_equal(dbscan_labels(points, 0.05, 1), kd_tree)


def test_border_point_between_two_clusters_takes_the_label_of_the_first_cluster_found():
    # Two chains of four points 0.25 apart (cores with min_samples 4, eps 0.75) and one point exactly eps from the
    # end of each chain: it has only three neighbours, so it is a border point of both clusters. The right-hand
    # chain is listed first, so scikit-learn labels it 0 and gives the border point 0 as well.
    right = [[2.25, 0.0], [2.5, 0.0], [2.75, 0.0], [3.0, 0.0]]
    left = [[0.0, 0.0], [0.25, 0.0], [0.5, 0.0], [0.75, 0.0]]
    points = np.array([[1.5, 0.0], *left[::-1], *right][::-1])
    expected = sklearn_labels(points, 0.75, 4)
    assert set(expected) == {0, 1} and expected[-1] == 0, "the scene must hold a border point shared by two clusters"
    np.testing.assert_array_equal(dbscan_labels(points, 0.75, 4), expected)


def test_three_dimensional_points_and_the_sklearn_path_for_large_sets():
    rng = np.random.default_rng(3)
    small = rng.uniform(0, 5, size=(30, 3))
    np.testing.assert_array_equal(dbscan_labels(small, 0.8, 3), sklearn_labels(small, 0.8, 3))
    large = rng.uniform(0, 20, size=(SMALL_N_MAX + 50, 2))
    np.testing.assert_array_equal(dbscan_labels(large, 1.0, 2), sklearn_labels(large, 1.0, 2))
    np.testing.assert_array_equal(_dbscan_dense(large, 1.0, 2), sklearn_labels(large, 1.0, 2))


def test_empty_input_gives_no_labels():
    assert dbscan_labels(np.empty((0, 2)), 1.0, 2).shape == (0,)


@pytest.mark.parametrize(
    ("points", "eps", "min_samples", "message"),
    [
        (np.array([[0.0, 0.0], [np.nan, 1.0]]), 1.0, 2, "point 1 is not finite"),
        (np.zeros((3, 2)), 0.0, 2, "eps must be a positive"),
        (np.zeros((3, 2)), float("nan"), 2, "eps must be a positive"),
        (np.zeros((3, 2)), 1.0, 0, "min_samples must be a whole number"),
        (np.zeros((3, 2)), 1.0, 1.5, "min_samples must be a whole number"),
        (np.zeros(3), 1.0, 2, r"\(N, D\) array"),
    ],
)
def test_bad_input_is_rejected_with_a_clear_message(points, eps, min_samples, message):
    with pytest.raises(ValueError, match=message):
        dbscan_labels(points, eps, min_samples)


@pytest.mark.parametrize("n", [4, 20, 64])
@pytest.mark.parametrize("implementation", ["small-N", "sklearn"])
def test_bench_dbscan(benchmark, implementation, n):
    """Side by side: this module's path vs scikit-learn's estimator (run with --benchmark-enable); the labels of the
    timed one must equal the other's."""
    points = np.random.default_rng(n).uniform(0, 3 * np.sqrt(n), size=(n, 2))
    timed, other = (_dbscan_dense, sklearn_labels) if implementation == "small-N" else (sklearn_labels, dbscan_labels)
    labels = benchmark(timed, points, 1.5, 2)
    np.testing.assert_array_equal(labels, other(points, 1.5, 2))
