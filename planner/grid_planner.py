"""Grid planner: Dijkstra on the 8-connected grid of plannable cells, then an any-angle shortcut pass.

Same cost model as the OMPL planners (``planner.problem``): an edge between neighbouring cell centres costs its
length times (1 + the mean of the two cells' w c / 252), the exact integral of the piecewise-constant cost along
it. Diagonal steps need all four cells around them plannable, so no edge cuts a corner. scipy's csgraph Dijkstra
does the search in C. 8-connected paths are longer than any-angle ones (up to 8 %, at 22.5 deg to the grid), so
the facade (``planner.facade.plan``) passes this path through the same smoothing as every planner, whose first step
is the any-angle shortcut pass; the result is the yardstick for the sampling planners' cost.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from planner.problem import CostField, NoPathError, PlanningError

__all__ = ["grid_graph", "grid_search"]

_MOVES = ((0, 1), (1, 0), (1, 1), (1, -1))  # (drow, dcol); the graph is undirected


def grid_graph(field: CostField) -> tuple[coo_matrix, np.ndarray]:
    """The sparse graph over plannable cells and the node index of every cell (-1 where not plannable)."""
    ok = field.plannable
    rows, cols = ok.shape
    node = np.full(ok.shape, -1, dtype=np.int64)
    node[ok] = np.arange(int(ok.sum()))
    res = field.resolution
    sources, targets, weights = [], [], []
    for dr, dc in _MOVES:
        r0, r1 = 0, rows - dr
        c0, c1 = max(0, -dc), cols - max(0, dc)
        a = (slice(r0, r1), slice(c0, c1))
        b = (slice(r0 + dr, r1 + dr), slice(c0 + dc, c1 + dc))
        edge = ok[a] & ok[b]
        if dr and dc:
            edge &= ok[r0 + dr : r1 + dr, c0:c1] & ok[r0:r1, c0 + dc : c1 + dc]
        length = res * np.hypot(dr, dc)
        sources.append(node[a][edge])
        targets.append(node[b][edge])
        weights.append(length * (1.0 + 0.5 * (field.weight[a][edge] + field.weight[b][edge])))
    n = int(ok.sum())
    graph = coo_matrix((np.concatenate(weights), (np.concatenate(sources), np.concatenate(targets))), shape=(n, n))
    return graph, node


def grid_search(field: CostField) -> np.ndarray:
    """The cheapest 8-connected path (N, 2) in the world frame, from the exact start to the exact goal."""
    problem = field.problem
    graph, node = grid_graph(field)
    spec = field.spec
    start_cell, goal_cell = spec.world_to_cell(np.array([problem.start, problem.goal]))
    s, g = node[tuple(start_cell)], node[tuple(goal_cell)]
    if s < 0 or g < 0:
        raise PlanningError("start or goal is not in a plannable cell (check_endpoints should have caught this)")
    dist, previous = dijkstra(graph.tocsr(), directed=False, indices=s, return_predecessors=True)
    if not np.isfinite(dist[g]):
        raise NoPathError("no path: the goal is not reachable from the start on this costmap")
    chain = [g]
    while chain[-1] != s:
        chain.append(previous[chain[-1]])
    if len(chain) == 1:  # start and goal in one cell: the straight line between them stays inside it
        return np.array([problem.start, problem.goal], dtype=float)
    flat = np.flatnonzero(node.ravel() >= 0)[np.array(chain[::-1])]
    path = spec.cell_to_world(np.stack(np.unravel_index(flat, node.shape), axis=1))
    path[0], path[-1] = problem.start, problem.goal
    return path
