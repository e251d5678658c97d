"""Gated minimum-cost assignment of tracks (rows) to candidates (columns), shared by the people and group trackers.

``gated_assignment(cost, allowed)`` matches as many allowed pairs as it can and, among those matchings, the one of
least total cost; pairs outside ``allowed`` are never returned. That is ``scipy.optimize.linear_sum_assignment`` on
the cost with every pair outside the gate priced above any matching of allowed pairs.

Most frames need no solver: when every row with an allowed pair has a single cheapest allowed column and no two
rows share it, those pairs are the answer, and the only one (every row sits at its own lower bound, and no matching
has more allowed pairs than rows that have one). The solver runs only otherwise, and ``scipy.optimize`` is imported
on that first use: the import takes 0.7 s, most of SciPy, which was half of a `sid detect` start-up
(docs/benchmarks.md, "Start-up"). ``load_solver()`` imports it ahead of time, for a long-running node that should not
pause on its first crowded frame.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache

import numpy as np


def gated_assignment(cost: np.ndarray, allowed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns (int arrays, row order) of the best matching of allowed pairs of a (R, C) ``cost``.

    ``allowed``: (R, C) bool, the pairs that may be matched; a pair with a non-finite cost is never matched.
    """
    cost, allowed = np.asarray(cost, dtype=float), np.asarray(allowed, dtype=bool)
    if cost.ndim != 2 or allowed.shape != cost.shape:
        shapes = f"{cost.shape} and {allowed.shape}"
        raise ValueError(f"assignment: cost and allowed must be matrices of one shape, got {shapes}")
    allowed = allowed & np.isfinite(cost)
    rows = np.flatnonzero(allowed.any(axis=1))
    if not len(rows):
        return rows, rows.copy()
    gated = np.where(allowed[rows], cost[rows], np.inf)
    cols = gated.argmin(axis=1)
    best = gated[np.arange(len(rows)), cols]
    single = np.count_nonzero(gated == best[:, None], axis=1) == 1
    if single.all() and len(np.unique(cols)) == len(cols):
        return rows, cols
    # Outside the gate a pair costs more than every allowed pair of any matching together, so the solver first
    # matches as many allowed pairs as it can, then minimises their cost.
    lowest = float(cost[allowed].min())
    span = float(cost[allowed].max()) - lowest
    priced = np.where(allowed, cost - lowest, (span + 1.0) * (min(cost.shape) + 1))
    rows, cols = load_solver()(priced)
    kept = allowed[rows, cols]
    return rows[kept], cols[kept]


@cache
def load_solver() -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """``scipy.optimize.linear_sum_assignment``, imported on the first call (see the module docstring)."""
    from scipy.optimize import linear_sum_assignment

    return linear_sum_assignment
