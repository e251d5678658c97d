"""Path simplification and smoothing on the planners' cost model, never raising the cost nor leaving free space.

Every step only accepts a change whose new segments are plannable over their whole length and whose cost J
(``planner.problem``) is lower, so each step keeps the path valid and no step makes it more expensive; ``smooth``
compares the result with its input and returns the cheaper one all the same.

Why not OMPL's ``PathSimplifier``: its vertex reduction and vertex collapsing test validity only, so under a cost
integral they can raise J (a shortcut through a social zone is shorter but dearer), and each of its checks would be
a Python callback. Here every candidate move of a pass is evaluated at once with numpy on the precomputed grids.
"""

from __future__ import annotations

import math

import numpy as np

from planner.problem import CostField
from planner.validity import interpolate

__all__ = ["DP_REACH", "REFINE_MIN_STEP", "REFINE_SWEEPS", "dp_shortcut", "refine", "smooth"]

_DIRECTIONS = np.array([[1, 0], [0, 1], [-1, 0], [0, -1], [1, 1], [-1, 1], [-1, -1], [1, -1]], float)
_DIRECTIONS[4:] /= np.sqrt(2.0)
_NEIGHBOURS = np.array([[-1], [0], [1]])  # (3, 1): before, the vertex, after
_WINDOW = 64  # the any-angle pass looks at most this many vertices ahead
REFINE_SWEEPS = 2
REFINE_MIN_STEP = 0.25
"""``smooth``'s refinement: at most this many sweeps per step size, down to this step (in cells): the cheapest
setting that keeps the navigation study's plans as close to the grid reference as finer ones (docs/benchmarks.md,
"Planning: the smoother")."""
DP_REACH = 12
"""The last shortcut pass joins refined vertices (about 6 cells apart) at most this many apart: refinement has
already bent the path, so longer shortcuts rarely pay, and all pairs cost O(N^2) segments."""


def _greedy(field: CostField, path: np.ndarray, step_cost: np.ndarray, window: int) -> np.ndarray:
    """Any-angle pass over a path (N > 2, 2) whose segments cost ``step_cost`` (N - 1,): from each kept vertex jump to
    the farthest of the next ``window`` vertices that a straight, plannable segment reaches at no more cost than the
    path between them. O(N) numpy calls."""
    prefix = np.concatenate([[0.0], np.cumsum(step_cost)])
    xy = path.T.copy()  # (2, N): coordinate-major, as ``CostField.segments_xy`` takes it
    kept, a = [0], 0
    while a < len(path) - 1:
        js = np.arange(a + 1, min(a + window, len(path) - 1) + 1)
        cost, ok = field.segments_xy(np.repeat(xy[:, a : a + 1], len(js), axis=1), xy.take(js, axis=1))
        good = ok & (cost <= prefix[js] - prefix[a] + 1e-9)
        good[0] = True  # the path's own next step is always kept available
        a = int(js[np.flatnonzero(good)[-1]])
        kept.append(a)
    return path[kept]


def dp_shortcut(field: CostField, path: np.ndarray, reach: int | None = None) -> np.ndarray:
    """The cheapest polyline through a subsequence of the vertices (dynamic programming over vertex pairs at most
    ``reach`` vertices apart; None: all pairs). The path's own segments are always allowed, so the result never costs
    more. O(N * reach) segments (O(N^2) without a reach)."""
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    if len(path) <= 2:
        return path.copy()
    return path[_cheapest_subsequence(field, path, reach)[0]]


def _cheapest_subsequence(field: CostField, path: np.ndarray, reach: int | None) -> tuple[list[int], np.ndarray]:
    """``dp_shortcut``'s vertex indices for a path (N > 2, 2), and the costs J of the result's segments."""
    n = len(path)
    i, j = np.triu_indices(n, 1)
    if reach is not None:
        i, j = i[j - i <= reach], j[j - i <= reach]
    xy = path.T.copy()  # (2, N): coordinate-major, as ``CostField.segments_xy`` takes it
    cost, ok = field.segments_xy(xy.take(i, axis=1), xy.take(j, axis=1))
    ok |= j == i + 1
    matrix = np.full((n, n), np.inf)
    matrix[i[ok], j[ok]] = cost[ok]
    # The recurrence on Python floats: one numpy call per vertex would cost more than these few additions.
    columns = matrix.T.tolist()
    best, previous = [0.0] * n, [0] * n
    for k in range(1, n):
        column, best_k = columns[k], math.inf
        for m in range(0 if reach is None else max(0, k - reach), k):
            total = best[m] + column[m]
            if total < best_k:  # strict: the first of equal totals, as np.argmin
                best_k, previous[k] = total, m
        best[k] = best_k
    order = [n - 1]
    while order[-1] != 0:
        order.append(previous[order[-1]])
    order.reverse()
    return order, matrix[order[:-1], order[1:]]


def refine(field: CostField, path: np.ndarray, max_step: float, min_step: float, sweeps: int = 4) -> np.ndarray:
    """Move interior vertices downhill in J: at step sizes from ``max_step`` halving to ``min_step`` (metres), try
    the eight compass moves for every other vertex at once (alternate vertices share no segment) and move each vertex
    to the move that lowers the cost of its two segments most while keeping them plannable (steepest descent). All
    16 segments of every candidate move of a pass that may win are priced in one numpy pass (``_descend``).

    Within a step size only vertices that may move are priced again: one that moved, or whose neighbour moved. A
    vertex that did not move while its neighbours stayed would get the same answer, so the result is the same as
    pricing every vertex in every pass."""
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    if len(path) <= 2:
        return path.copy()
    seg_cost = field.segments(path[:-1], path[1:])[0]
    xy = path.T.copy()  # (2, N): coordinate-major, as ``_descend`` reads and writes it
    step = max_step
    while step >= min_step:
        moves = (_DIRECTIONS * step).T[:, :, None]  # (2, 8, 1): x/y, move (metres)
        active = np.ones(len(path), dtype=bool)
        active[[0, -1]] = False  # a new step size: every interior vertex may move again; the ends never move
        for _ in range(sweeps):
            moved = False
            for first in (1, 0):
                idx = active[first::2].nonzero()[0] * 2 + first
                if len(idx):
                    moved |= _descend(field, xy, seg_cost, idx, moves, active)
            if not moved:
                break
        step /= 2
    return xy.T.copy()


def _descend(
    field: CostField, xy: np.ndarray, seg_cost: np.ndarray, idx: np.ndarray, moves: np.ndarray, active: np.ndarray
) -> bool:
    """One pass of ``refine`` over the vertices ``idx`` (no two adjacent, none an end) with the offsets ``moves``
    (2, 8, 1) in metres: move each to its best plannable candidate when that lowers the cost of its two segments, in
    place in ``xy`` (2, N: the path's x and y in the world frame, metres), ``seg_cost`` (J of each segment) and
    ``active`` (vertices that may move). Whether any moved.

    A segment costs at least its length, so a move whose two new segments are together at least as long as the
    cost to beat cannot win, nor be the best of the moves that do: only the others are priced (a minority of the
    moves: docs/benchmarks.md, "Planning: the smoother"), by ``CostField.segments_along`` from the starts, offsets
    and lengths computed here. Arrays are coordinate-major, vertices last: numpy's inner loops then run over vertices
    rather than over two coordinates."""
    k = len(idx)
    before, vertex, after = xy.take(idx + _NEIGHBOURS, axis=1).transpose(1, 0, 2)  # each (2, k): x/y, vertex
    # Per candidate segment: start x/y, offset x/y to its end, length; (5, in/out segment, move, vertex).
    segment = np.empty((5, 2, 8, k))
    start, offset, length = segment[:2], segment[2:4], segment[4]
    candidate = start[:, 1]  # (2, 8, k): the out segment starts at the candidate
    np.add(vertex[:, None, :], moves, out=candidate)
    start[:, 0] = before[:, None, :]
    np.subtract(candidate, before[:, None, :], out=offset[:, 0])
    np.subtract(after[:, None, :], candidate, out=offset[:, 1])
    np.hypot(offset[0], offset[1], out=length)
    threshold = seg_cost[idx - 1] + seg_cost[idx] - 1e-9
    hopeful = (length[0] + length[1] < threshold).ravel().nonzero()[0]  # flat (move, vertex) indices
    cost = np.full((2, 8, k), np.inf)
    if len(hopeful):
        priced = segment.reshape(5, 2, -1).take(hopeful, axis=2).reshape(5, -1)  # (5, in/out x hopeful)
        hopeful_cost, ok = field.segments_along(priced[:2], priced[2:4], priced[4])
        hopeful_cost[~ok] = np.inf
        cost.reshape(2, -1)[:, hopeful] = hopeful_cost.reshape(2, -1)  # a view: writes into cost
    total = cost[0] + cost[1]  # inf unless both segments are priced and plannable
    better = total.min(axis=0) < threshold
    active[idx] = better  # a vertex that stays may move again only once a neighbour moves
    moving = better.nonzero()[0]
    if not len(moving):
        return False
    chosen, pick = idx[moving], total[:, moving].argmin(axis=0)
    xy[:, chosen] = candidate[:, pick, moving]
    seg_cost[chosen - 1], seg_cost[chosen] = cost[:, pick, moving]
    active[chosen - 1] = active[chosen + 1] = True
    active[0] = active[-1] = False
    return True


def smooth(field: CostField, path: np.ndarray) -> np.ndarray:
    """Shortcut, then refine vertices spaced about ``6 * resolution`` apart, then shortcut again; return the result
    or the input, whichever has the lower J."""
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    if len(path) < 2:
        return path.copy()
    res = field.resolution
    step_cost = field.segments(path[:-1], path[1:])[0]
    short = path if len(path) == 2 else _greedy(field, path, step_cost, _WINDOW)
    short = dp_shortcut(field, short)
    refined = refine(field, interpolate(short, 6 * res), 4 * res, REFINE_MIN_STEP * res, sweeps=REFINE_SWEEPS)
    if len(refined) <= 2:
        result, result_cost = refined, field.segments(refined[:-1], refined[1:])[0]
    else:
        order, result_cost = _cheapest_subsequence(field, refined, DP_REACH)
        result = refined[order]
    # The same sums as ``field.path_cost`` of both paths, from segment costs already known.
    return result if float(result_cost.sum()) <= float(step_cost.sum()) else path.copy()
