"""The grid planner's graph against a plain per-cell reference: which cells connect and what each edge costs."""

from __future__ import annotations

import math

import numpy as np
import pytest

from costmap.grid import LETHAL, Costmap2D, GridSpec
from planner.facade import plan
from planner.grid_planner import grid_graph
from planner.problem import CostField, PlanningProblem


def reference_edges(field: CostField) -> dict[tuple[int, int], float]:
    """Every edge of the 8-connected grid, cell pair -> cost, one cell at a time: a step joins two plannable
    neighbours, a diagonal step also needs the two cells beside it plannable (no corner cut), and it costs its length
    times (1 + the mean of the two cells' weights)."""
    ok, weight, res = field.plannable, field.weight, field.resolution
    rows, cols = ok.shape
    edges = {}
    for r in range(rows):
        for c in range(cols):
            for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
                r2, c2 = r + dr, c + dc
                if not (0 <= r2 < rows and 0 <= c2 < cols) or not (ok[r, c] and ok[r2, c2]):
                    continue
                if dr and dc and not (ok[r2, c] and ok[r, c2]):
                    continue
                cost = res * math.hypot(dr, dc) * (1.0 + 0.5 * (weight[r, c] + weight[r2, c2]))
                edges[tuple(sorted((r * cols + c, r2 * cols + c2)))] = cost
    return edges


def random_field(seed: int) -> CostField:
    """A 1.5 x 1.2 m map at 5 cm with random lethal specks and graded costs, robot radius 0.05 m."""
    rng = np.random.default_rng(seed)
    spec = GridSpec.from_size(0.05, (0.0, 0.0), (1.5, 1.2))
    costs = rng.integers(0, 200, spec.shape).astype(np.uint8)
    costs[rng.random(spec.shape) < 0.08] = LETHAL
    costs[:3, :3] = 0
    costs[-3:, -3:] = 0
    return CostField(PlanningProblem(Costmap2D(spec, costs), (0.075, 0.075), (1.425, 1.125), 0.05))


@pytest.mark.parametrize("seed", range(5))
def test_graph_is_the_per_cell_reference(seed):
    field = random_field(seed)
    graph, node = grid_graph(field)
    cell_of = np.flatnonzero(node.ravel() >= 0)
    found = {}
    for a, b, w in zip(graph.row, graph.col, graph.data, strict=True):
        found[tuple(sorted((int(cell_of[a]), int(cell_of[b]))))] = float(w)
    expected = reference_edges(field)
    assert len(expected) > 0 and found.keys() == expected.keys()
    assert np.allclose([found[k] for k in expected], list(expected.values()), rtol=1e-12)


def test_no_diagonal_step_squeezes_between_two_blocked_cells():
    # Two blocked cells touching at a corner: the only way from one side to the other is the diagonal between them.
    spec = GridSpec.from_size(0.05, (0.0, 0.0), (0.5, 0.5))
    costs = np.full(spec.shape, LETHAL, np.uint8)
    costs[1:5, 1:5] = 0  # a free room, bottom left
    costs[5:9, 5:9] = 0  # another, top right, meeting the first only at the corner (4, 4) / (5, 5)
    problem = PlanningProblem(Costmap2D(spec, costs), (0.125, 0.125), (0.375, 0.375), 0.0)
    field = CostField(problem)
    field.plannable[1:5, 1:5] = field.plannable[5:9, 5:9] = True  # both rooms plannable up to their walls
    graph, node = grid_graph(field)
    assert node[4, 4] >= 0 and node[5, 5] >= 0
    joined = {tuple(sorted((int(a), int(b)))) for a, b in zip(graph.row, graph.col, strict=True)}
    assert tuple(sorted((int(node[4, 4]), int(node[5, 5])))) not in joined


@pytest.mark.parametrize(
    ("start", "goal"), [((1.0, 1.0), (1.04, 1.04)), ((0.51, 0.51), (0.99, 0.99)), ((1.0, 1.0), (1.0, 1.0))]
)
def test_start_and_goal_in_one_cell_give_the_line_between_them(start, goal):
    # The cheapest chain of cells is that one cell; its single point used to be overwritten by the goal, so the path
    # lost its start and read 0 m however far apart the two were (0.68 m on 0.5 m cells).
    for resolution in (0.05, 0.5):
        spec = GridSpec.from_size(resolution, (0.0, 0.0), (5.0, 5.0))
        problem = PlanningProblem(Costmap2D(spec, np.zeros(spec.shape, np.uint8)), start, goal, 0.25)
        if (spec.world_to_cell(np.array([start]))[0] != spec.world_to_cell(np.array([goal]))[0]).any():
            continue
        result = plan(problem, "grid")
        np.testing.assert_array_equal(result.path, [start, goal])
        assert result.success and result.length_m == pytest.approx(math.dist(start, goal))
