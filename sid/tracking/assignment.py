"""Gated minimum-cost assignment of tracks (rows) to candidates (columns), shared by the people and group trackers.

``gated_assignment(cost, allowed)`` matches as many allowed pairs as it can and, among those matchings, the one of
least total cost; pairs outside ``allowed`` are never returned. That is ``scipy.optimize.linear_sum_assignment`` on
the cost with every pair outside the gate priced above any matching of allowed pairs.

Most frames need no solver: when every row with an allowed pair has a single cheapest allowed column and no two
rows share it, those pairs are the answer, and the only one (every row sits at its own lower bound, and no matching
has more allowed pairs than rows that have one). The solver runs only otherwise, and ``scipy.optimize`` is imported
on that first use: the import loads most of SciPy, about half of a `sid detect` start-up (docs/benchmarks.md,
"Start-up and the detect loop"). ``load_solver()`` imports it ahead of time, for a long-running node that should
not pause on its first crowded frame.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import cache

import numpy as np

from sid.errors import InputError

__all__ = ["gated_assignment", "load_solver"]


def gated_assignment(cost: np.ndarray, allowed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows and columns (int arrays, row order) of the best matching of allowed pairs of a (R, C) ``cost``.

    ``allowed``: (R, C) bool, the pairs that may be matched; a pair with a non-finite cost is never matched.
    """
    cost, allowed = np.asarray(cost, dtype=float), np.asarray(allowed, dtype=bool)
    if cost.ndim != 2 or allowed.shape != cost.shape:
        shapes = f"{cost.shape} and {allowed.shape}"
        raise InputError(f"assignment: cost and allowed must be matrices of one shape, got {shapes}")
    pairs = _own_minima(np.where(allowed, cost, np.inf))
    if pairs is not None:
        return pairs
    # Outside the gate a pair costs more than every allowed pair of any matching together, so the solver first
    # matches as many allowed pairs as it can, then minimises their cost.
    allowed = allowed & np.isfinite(cost)
    if not allowed.any():  # only non-finite costs were allowed
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
    lowest = float(cost[allowed].min())
    span = float(cost[allowed].max()) - lowest
    priced = np.where(allowed, cost - lowest, (span + 1.0) * (min(cost.shape) + 1))
    rows, cols = load_solver()(priced)
    kept = allowed[rows, cols]
    return rows[kept], cols[kept]


def _own_minima(gated: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Each row's cheapest column of ``gated`` (inf: not allowed), rows with none left out, when every such minimum
    is finite and strict and no two rows share a column; None otherwise (the solver decides). A few numpy calls,
    then Python on the rows: a tracker has tens of rows, where numpy's per-call cost is the whole cost."""
    if gated.size == 0:
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
    ordered = np.sort(gated, axis=1)  # a row's NaN sorts last
    if any(last != last for last in ordered[:, -1].tolist()):  # NaN costs: the solver's path leaves them out
        return None
    seconds = ordered[:, 1].tolist() if gated.shape[1] > 1 else [math.inf] * len(gated)
    rows: list[int] = []
    cols: list[int] = []
    taken: set[int] = set()
    firsts, cols_by_row = ordered[:, 0].tolist(), gated.argmin(axis=1).tolist()
    for row, (col, first, second) in enumerate(zip(cols_by_row, firsts, seconds, strict=True)):
        if first == math.inf:  # nothing allowed
            continue
        if first == second or first == -math.inf or col in taken:
            return None
        rows.append(row)
        cols.append(col)
        taken.add(col)
    return np.array(rows, dtype=np.intp), np.array(cols, dtype=np.intp)


@cache
def load_solver() -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """``scipy.optimize.linear_sum_assignment``, imported on the first call (see the module docstring)."""
    from scipy.optimize import linear_sum_assignment

    return linear_sum_assignment
