"""DBSCAN labels for the handful of people a robot sees, identical to scikit-learn's.

scikit-learn's ``DBSCAN`` is the reference, but a call costs far more than the clustering of a few points
(estimator set-up, input validation, a neighbours index; timings in docs/parameters.md). A frame holds 2-20 people,
so this module computes the same labels from the dense pairwise-distance matrix with a few numpy operations, and
hands larger sets to scikit-learn.

Labels follow scikit-learn exactly (a property test in ``tests/perception/test_cluster.py`` checks it):
- a point is *core* when at least ``min_samples`` points (itself included) lie within ``eps`` (distance <= eps);
- clusters are the connected components of core points linked by distance <= eps, numbered 0, 1, ... in the
  order of their lowest-index core point (scikit-learn expands clusters from core points in index order);
- a non-core point within eps of a core point is a *border* point; scikit-learn's depth-first expansion finishes
  one cluster before starting the next, so a border point reachable from several clusters takes the lowest label;
- every other point is noise, -1.

Distances are compared squared (``dx^2 + dy^2 <= eps^2``), as scikit-learn's KD-tree does. Exact ties at eps
agree whenever that arithmetic is exact (grid coordinates, the property test's tie cases). A distance within one
rounding error of eps has no single answer: scikit-learn's brute-force back-end (``|a|^2 - 2 a.b + |b|^2``, which
``DBSCAN`` picks below ~12 points) and its KD-tree disagree there (points (2, 0), (2, 0.05), eps 0.05); this
module then agrees with the KD-tree, i.e. with exact arithmetic.
"""

from __future__ import annotations

import numpy as np

from sid.checks import check_number, check_whole
from sid.errors import InputError

__all__ = ["SMALL_N_MAX", "dbscan_labels"]

# Above this many points scikit-learn is used: its neighbour index wins once the O(n^2) work grows (the two
# cross between 128 and 256 points, docs/parameters.md).
SMALL_N_MAX = 128


def dbscan_labels(points: np.ndarray, eps: float, min_samples: int) -> np.ndarray:
    """DBSCAN cluster labels of (N, D) points (any consistent unit, e.g. metres): (N,) int, -1 = noise.

    Same labels as ``sklearn.cluster.DBSCAN(eps=eps, min_samples=min_samples).fit_predict(points)``.
    """
    points = np.asarray(points, dtype=float)
    if points.ndim != 2:
        raise InputError(f"dbscan: points must be an (N, D) array, got shape {points.shape}")
    check_number("dbscan", "eps", eps, low=0, low_open=True)
    check_whole("dbscan", "min_samples", min_samples, low=1)
    if not np.all(np.isfinite(points)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(points), axis=1))[0])
        raise InputError(f"dbscan: point {bad} is not finite: {points[bad].tolist()}")
    n = len(points)
    if n == 0:
        return np.empty(0, dtype=np.intp)
    if n > SMALL_N_MAX:
        from sklearn.cluster import DBSCAN  # here, not at the top: scikit-learn takes seconds to import

        return DBSCAN(eps=eps, min_samples=int(min_samples)).fit_predict(points).astype(np.intp)
    return _dbscan_dense(points, float(eps), int(min_samples))


def _dbscan_dense(points: np.ndarray, eps: float, min_samples: int) -> np.ndarray:
    """scikit-learn's algorithm (``_dbscan_inner.pyx``) on a dense neighbourhood matrix, in plain Python."""
    diff = points[:, None, :] - points[None, :, :]
    near = np.einsum("ijk,ijk->ij", diff, diff) <= eps * eps  # (n, n) eps-neighbourhoods, self included
    counts = near.sum(axis=1)
    core = (counts >= min_samples).tolist()
    neighbours = np.nonzero(near)[1].tolist()  # row-major: point k's neighbours are neighbours[start[k]:end[k]]
    end = np.cumsum(counts).tolist()
    start = [0, *end[:-1]]
    labels = [-1] * len(core)
    label = 0
    for seed in range(len(core)):
        if labels[seed] != -1 or not core[seed]:
            continue
        # Depth-first expansion from the lowest-index unlabelled core point; border points are labelled but not
        # expanded, so one reachable from two clusters keeps the label of the first.
        stack = [seed]
        while stack:
            k = stack.pop()
            if labels[k] != -1:
                continue
            labels[k] = label
            if core[k]:
                stack.extend(v for v in neighbours[start[k] : end[k]] if labels[v] == -1)
        label += 1
    return np.array(labels, dtype=np.intp)
