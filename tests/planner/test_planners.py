"""Planner core on hand-made costmaps: validity, cost model, every planner, impossible problems, repeatability."""

from __future__ import annotations

import itertools
import math
import pickle
import re
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy import ndimage

from costmap.grid import INSCRIBED, LETHAL, NO_INFORMATION, Costmap2D, GridSpec
from planner import ompl_planners
from planner.facade import PLANNERS, plan, resolve_planner
from planner.ompl_planners import OMPL_PLANNERS
from planner.problem import CostField, EndpointCollisionError, PlanningError, PlanningProblem, WalledOffError
from planner.smoothing import _DIRECTIONS, dp_shortcut, refine, smooth
from planner.validity import check_path, interpolate

RADIUS = 0.25


def inflate(lethal: np.ndarray, spec: GridSpec, radius: float = RADIUS) -> np.ndarray:
    """Nav2-style inflation of a lethal mask (254 / 253 within radius / exponential fall-off to 0.55 m)."""
    d = ndimage.distance_transform_edt(~lethal) * spec.resolution
    cost = np.where(d <= 0.55, 252 * np.exp(-10 * (d - radius)), 0).astype(np.uint8)
    cost[d <= radius] = INSCRIBED
    cost[lethal] = LETHAL
    return cost


def walled_map(blob_cost: int = 0) -> Costmap2D:
    """10 x 8 m at 5 cm: two staggered walls, and optionally a graded blob (peak ``blob_cost``) at (5, 4)."""
    spec = GridSpec.from_size(0.05, (0.0, 0.0), (10.0, 8.0))
    x, y = spec.cell_centres()
    lethal = ((x > 3.0) & (x < 3.2) & (y < 5.0)) | ((x > 6.5) & (x < 6.7) & (y > 3.0))
    costs = inflate(lethal, spec)
    if blob_cost:
        blob = (blob_cost * np.exp(-(np.hypot(x - 5, y - 4) ** 2) / (2 * 0.6**2))).astype(np.uint8)
        costs = np.maximum(costs, blob)
    return Costmap2D(spec, costs)


def independent_collisions(costmap: Costmap2D, path: np.ndarray, radius: float = RADIUS) -> int:
    """Samples (every 1 cm) whose cell is inscribed/lethal/unknown or whose centre is within radius of a lethal
    cell centre: computed without the planner's own lookups."""
    samples = interpolate(path, 0.01)
    costs = costmap.cost_at(samples)
    lethal_xy = costmap.spec.cell_to_world(np.argwhere(costmap.costs == LETHAL))
    cells = costmap.spec.cell_to_world(costmap.spec.world_to_cell(samples))
    near = np.zeros(len(samples), bool)
    for chunk in np.array_split(np.arange(len(samples)), max(1, len(samples) // 200)):
        d = np.hypot(*(cells[chunk, None, :] - lethal_xy[None]).transpose(2, 0, 1)).min(axis=1)
        near[chunk] = d <= radius
    return int(((costs >= INSCRIBED) | near).sum())


@pytest.fixture(scope="module")
def walls() -> PlanningProblem:
    return PlanningProblem(walled_map(), (1.0, 2.0), (9.0, 6.0), RADIUS)


# ---- validity and cost model ----------------------------------------------------------------------------------


def test_free_mask_follows_footprint_inscribed_and_unknown():
    spec = GridSpec.from_size(0.05, (0.0, 0.0), (2.0, 2.0))
    costs = np.zeros(spec.shape, np.uint8)
    costs[20, 20] = LETHAL  # no inflation at all: the footprint check must still keep the disc off it
    costs[5, 30] = INSCRIBED
    costs[35, 5] = NO_INFORMATION
    field = CostField(PlanningProblem(Costmap2D(spec, costs), (0.3, 0.3), (1.7, 1.7), RADIUS))
    assert not field.free[20, 25] and field.free[20, 26]  # 5 cells = 0.25 m: inside the disc; 6 cells: outside
    assert not field.free[5, 30] and not field.free[35, 5]
    assert field.plannable.sum() < field.free.sum()  # the planners' mask is one cell stricter
    lenient = CostField(PlanningProblem(Costmap2D(spec, costs), (0.3, 0.3), (1.7, 1.7), RADIUS, allow_unknown=True))
    assert lenient.free[35, 5]


def test_validity_checker_returns_python_bool(walls):
    from planner.validity import state_validity_checker

    field = CostField(walls)
    checker = state_validity_checker(field)
    assert checker([1.0, 2.0]) is True
    assert checker([3.1, 1.0]) is False


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.01, 9.99), min_size=4, max_size=4))
def test_scalar_and_vectorised_segment_costs_agree(coords):
    field = CostField(PlanningProblem(walled_map(blob_cost=200), (1.0, 2.0), (9.0, 6.0), RADIUS))
    x0, y0, x1, y1 = coords
    y0, y1 = y0 * 0.8, y1 * 0.8
    vectorised = field.segments(np.array([[x0, y0]]), np.array([[x1, y1]]))[0][0]
    assert field.segment_cost(x0, y0, x1, y1) == pytest.approx(vectorised, rel=1e-9, abs=1e-9)


def plain_segment_cost(field: CostField, spec: GridSpec, x0: float, y0: float, x1: float, y1: float) -> float:
    """J of a segment by its definition: length x (1 + the mean weight of the cells under n midpoints, n = the
    length in cells rounded up), each midpoint's cell found on its own (floor, clamped at the map's upper edge)."""
    length = math.hypot(x1 - x0, y1 - y0)
    n = max(1, math.ceil(length / spec.resolution - 1e-9))
    total = 0.0
    for i in range(n):
        t = (i + 0.5) / n
        x, y = x0 + t * (x1 - x0), y0 + t * (y1 - y0)
        col = min(math.floor((x - spec.origin_x) / spec.resolution), field.weight.shape[1] - 1)
        row = min(math.floor((y - spec.origin_y) / spec.resolution), field.weight.shape[0] - 1)
        total += field.weight[row, col]
    return length * (1.0 + total / n)


@pytest.mark.parametrize("seed", range(5))
def test_both_segment_cost_paths_are_the_definition(seed: int) -> None:
    # Short segments (the scalar loop), long ones (its numpy branch) and the vectorised lookup, all held to the
    # plain rule on random segments inside the map.
    costmap = walled_map(blob_cost=200)
    field = CostField(PlanningProblem(costmap, (1.0, 2.0), (9.0, 6.0), RADIUS))
    rng = np.random.default_rng(seed)
    spec = costmap.spec
    width, height = spec.shape[1] * spec.resolution, spec.shape[0] * spec.resolution
    for _ in range(40):
        start = rng.uniform((0.01, 0.01), (width - 0.01, height - 0.01))
        end = start + rng.normal(0, 0.3 if rng.random() < 0.5 else 3.0, 2)
        end = np.clip(end, 0.01, (width - 0.01, height - 0.01))
        expected = plain_segment_cost(field, spec, *start, *end)
        assert field.segment_cost(*start, *end) == pytest.approx(expected, rel=1e-9)
        assert field.segments(start[None], end[None])[0][0] == pytest.approx(expected, rel=1e-9)


def test_zero_weight_cost_is_length():
    problem = PlanningProblem(walled_map(blob_cost=200), (1.0, 2.0), (9.0, 6.0), RADIUS, cost_weight=0.0)
    field = CostField(problem)
    assert field.segment_cost(1.0, 1.0, 5.0, 4.0) == pytest.approx(5.0)


def test_cost_grows_with_the_cells_crossed():
    field = CostField(PlanningProblem(walled_map(blob_cost=200), (1.0, 2.0), (9.0, 6.0), RADIUS))
    through_blob = field.segment_cost(4.0, 4.0, 6.0, 4.0)
    beside_blob = field.segment_cost(4.0, 6.5, 6.0, 6.5)
    assert through_blob > 2.0 * 2.0 and beside_blob == pytest.approx(2.0, abs=0.01)


# ---- planners ------------------------------------------------------------------------------------------------


# Iteration caps (not time) bound the runs so that results do not depend on the machine's speed.
CAPS = {"rrtstar": 300, "informed_rrtstar": 300, "bitstar": 3000, "rrtconnect": 1000, "fmtstar": 300, "grid": None}


@pytest.mark.parametrize("name", PLANNERS)
def test_every_planner_finds_a_collision_free_path(walls, name):
    result = plan(walls, name, time_limit=30.0, seed=5, max_iterations=CAPS[name])
    assert result.success, result.message
    assert np.allclose(result.path[0], walls.start) and np.allclose(result.path[-1], walls.goal)
    assert independent_collisions(walls.costmap, result.path) == 0
    assert check_path(CostField(walls), result.path).valid
    assert result.cost <= result.raw_cost + 1e-9  # smoothing never raises the cost
    straight = math.dist(walls.start, walls.goal)
    assert straight < result.length_m < 2.0 * straight


def test_graded_cost_bends_the_path():
    costmap = walled_map(blob_cost=250)
    start, goal = (4.0, 4.0), (6.0, 4.0)  # the blob (peak 250, not an obstacle) sits between them
    shortest = plan(PlanningProblem(costmap, start, goal, RADIUS, cost_weight=0.0), "grid")
    social = plan(PlanningProblem(costmap, start, goal, RADIUS), "grid")
    assert shortest.length_m == pytest.approx(2.0, abs=0.01)
    assert social.length_m > 2.2
    on_path = costmap.cost_at(interpolate(social.path, 0.02))
    assert on_path.max() < 250


def test_sampling_planner_matches_grid_reference_on_graded_map():
    problem = PlanningProblem(walled_map(blob_cost=250), (1.0, 2.0), (9.0, 6.0), RADIUS)
    reference = plan(problem, "grid")
    result = plan(problem, "bitstar", time_limit=30.0, seed=2, max_iterations=5000)
    assert result.success and result.cost <= 1.05 * reference.cost


def test_smoothing_keeps_paths_valid_and_never_raises_cost(walls):
    field = CostField(walls)
    rng = np.random.default_rng(0)
    for seed in range(3):
        raw = plan(walls, "rrtconnect", seed=seed + 1, simplify=False).path
        jittered = raw.copy()
        jittered[1:-1] += rng.normal(0, 0.01, jittered[1:-1].shape)
        for path in (raw, jittered):
            smoothed = smooth(field, path)
            assert field.path_cost(smoothed) <= field.path_cost(path) + 1e-9
            if check_path(field, path).valid:
                assert check_path(field, smoothed).valid


def test_refine_and_a_short_reach_shortcut_never_raise_cost_and_keep_vertices(walls):
    field = CostField(walls)
    raw = plan(walls, "rrtconnect", seed=4, simplify=False).path
    dense = interpolate(raw, 0.3)
    refined = refine(field, dense, max_step=0.2, min_step=0.00625)
    assert len(refined) == len(dense) and np.array_equal(refined[[0, -1]], dense[[0, -1]])  # ends stay
    assert field.path_cost(refined) <= field.path_cost(dense) + 1e-9 and check_path(field, refined).valid
    for reach in (2, 12, None):
        short = dp_shortcut(field, refined, reach=reach)
        assert field.path_cost(short) <= field.path_cost(refined) + 1e-9
        assert all((refined == vertex).all(axis=1).any() for vertex in short)  # a subsequence of the vertices
    # A longer reach can only find a cheaper (or equal) subsequence.
    costs = [field.path_cost(dp_shortcut(field, refined, reach=r)) for r in (2, 12, None)]
    assert costs[0] >= costs[1] - 1e-9 >= costs[2] - 2e-9


def plain_segments(field: CostField, p: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``CostField.segments`` written plainly, segment by segment: the midpoints of ceil(L / resolution) pieces for
    the cost (even samples weigh 0), midpoints and piece ends for plannability, each in the cell ``world_to_cell``
    gives, outside samples clamped to the border and not plannable;
    ends that are not finite give J = the length and not plannable."""
    inv = 1.0 / field.resolution
    costs, oks = [], []
    for (x0, y0), (x1, y1) in zip(p.tolist(), q.tolist(), strict=True):
        dx, dy = x1 - x0, y1 - y0
        length = float(np.hypot(dx, dy))
        if not np.isfinite(length):
            costs.append(length)
            oks.append(False)
            continue
        n = max(1.0, float(np.ceil(length * inv - 1e-9)))
        weights, ok = [], True
        for k in range(int(2 * n) + 1):
            t = k / (2 * n)
            (row, col) = field.spec.world_to_cell(np.array([x0 + t * dx, y0 + t * dy]))[0].tolist()
            inside = 0 <= row < field.spec.height and 0 <= col < field.spec.width
            row, col = min(max(row, 0), field.spec.height - 1), min(max(col, 0), field.spec.width - 1)
            ok &= inside and bool(field.plannable[row, col])
            weights.append(float(field.weight[row, col]) if k % 2 else 0.0)
        # numpy's sum of the samples in order (pairwise beyond 8 terms, as any numpy sum of a row)
        costs.append(length * (1.0 + float(np.add.reduce(np.array(weights))) / n))
        oks.append(ok)
    return np.array(costs), np.array(oks)


def test_segments_equal_a_plain_segment_by_segment_pricing_to_the_last_bit():
    # Also on cell boundaries, for zero-length segments, for segments leaving the map (clamped lookups) and for ends
    # that are not finite numbers.
    field = CostField(PlanningProblem(walled_map(blob_cost=200), (1.0, 2.0), (9.0, 6.0), RADIUS))
    rng = np.random.default_rng(3)
    for trial in range(120):
        m = int(rng.integers(1, 60))
        p = rng.uniform((-0.3, -0.3), (10.3, 8.3), (m, 2)) if trial % 4 == 0 else rng.uniform((0, 0), (10, 8), (m, 2))
        q = p + rng.normal(0, rng.choice([0.02, 0.3, 3.0]), (m, 2))
        if trial % 4:
            q = np.clip(q, 0.0, (10 - 1e-9, 8 - 1e-9))
        if trial % 3 == 0:
            p, q = np.round(p / 0.05) * 0.05, np.round(q / 0.025) * 0.025  # on cell edges and centres
        q[: m // 5] = p[: m // 5]
        if trial % 20 == 0:
            p[-1, trial % 2] = (np.nan, np.inf)[trial // 20 % 2]
        expected, got = plain_segments(field, p, q), field.segments(p, q)
        assert np.array_equal(got[0], expected[0], equal_nan=True) and np.array_equal(got[1], expected[1])
        assert [field.segments(p[i : i + 1], q[i : i + 1])[0][0] for i in range(0, m, 7)] == pytest.approx(
            got[0][::7].tolist(), nan_ok=True, rel=0, abs=0
        )


def test_segments_of_unequal_length_are_priced_in_chunks_with_the_same_values(monkeypatch):
    # All pairs of a path's vertices: short and long segments together; cut into small chunks they price the same.
    import planner.problem

    field = CostField(PlanningProblem(walled_map(blob_cost=200), (1.0, 2.0), (9.0, 6.0), RADIUS))
    rng = np.random.default_rng(5)
    vertices = rng.uniform((0.2, 0.2), (9.8, 7.8), (40, 2))
    i, j = np.triu_indices(len(vertices), 1)
    whole = field.segments(vertices[i], vertices[j])
    monkeypatch.setattr(planner.problem, "SAMPLES_PER_CALL", 500)  # a few segments a chunk, some alone
    chunked = field.segments(vertices[i], vertices[j])
    assert np.array_equal(whole[0], chunked[0]) and np.array_equal(whole[1], chunked[1])


def refine_every_move(field: CostField, path: np.ndarray, max_step: float, min_step: float, sweeps: int) -> np.ndarray:
    """``refine`` written plainly: every interior vertex of a parity, every move, priced by ``CostField.segments``."""
    path = path.copy()
    seg_cost = field.segments(path[:-1], path[1:])[0]
    step = max_step
    while step >= min_step:
        for _ in range(sweeps):
            moved = False
            for first in (1, 0):
                for i in range(first or 2, len(path) - 1, 2):
                    candidates = path[i] + _DIRECTIONS * step
                    c_in, ok_in = field.segments(np.repeat(path[i - 1 : i], 8, axis=0), candidates)
                    c_out, ok_out = field.segments(candidates, np.repeat(path[i + 1 : i + 2], 8, axis=0))
                    total = np.where(ok_in & ok_out, c_in + c_out, np.inf)
                    best = int(np.argmin(total))
                    if total[best] < seg_cost[i - 1] + seg_cost[i] - 1e-9:
                        path[i], seg_cost[i - 1], seg_cost[i], moved = candidates[best], c_in[best], c_out[best], True
            if not moved:
                break
        step /= 2
    return path


def test_refine_equals_pricing_every_move(walls):
    # refine prices only vertices that may move and only moves that may win; the result must not change.
    field = CostField(PlanningProblem(walled_map(blob_cost=250), (1.0, 2.0), (9.0, 6.0), RADIUS))
    rng = np.random.default_rng(1)
    for seed in (1, 2):
        dense = interpolate(plan(walls, "rrtconnect", seed=seed, simplify=False).path, 0.3)
        jittered = dense.copy()
        jittered[1:-1] += rng.normal(0, 0.02, jittered[1:-1].shape)
        for path in (dense, jittered):
            for sweeps in (1, 2):
                expected = refine_every_move(field, path, 0.2, 0.0125, sweeps)
                assert np.array_equal(refine(field, path, 0.2, 0.0125, sweeps), expected)


def test_bitstar_stops_once_its_cost_settles_and_other_planners_use_their_budget(walls):
    settled = plan(walls, "bitstar", time_limit=30.0, seed=3, soft_limit=None)
    assert settled.success and settled.solve_time_s < 15.0  # stopped by the settle rule, not by the 30 s budget
    # solve_time_s counts from the instant the budget does: it was measured from a later one, and a run that used
    # its whole 0.3 s reported 0.2995 s
    whole = plan(walls, "bitstar", time_limit=0.3, seed=3, settle=None, soft_limit=None)
    assert whole.solve_time_s >= 0.3
    rrt = plan(walls, "rrtstar", time_limit=0.3, seed=3)  # RRT* is not stopped early (SETTLING_PLANNERS)
    assert rrt.solve_time_s >= 0.3
    for option in ("settle", "soft_limit"):
        for bad in (0.0, -1.0, math.nan, math.inf):
            with pytest.raises(ValueError, match=f"{option} must be a positive number of seconds"):
                plan(walls, "bitstar", **{option: bad})


def test_bitstar_soft_limit_stops_a_run_that_has_a_path_and_not_one_without(walls, monkeypatch):
    """On a fake clock (each reading 10 us later), so the stop does not depend on the machine's load: with a path,
    the solve ends within a poll of the soft limit, although the cost still falls and the budget is 30 s; a soft limit
    shorter than the time to a first path does not stop the search for one."""
    clock = itertools.count()
    monkeypatch.setattr(ompl_planners, "time", SimpleNamespace(perf_counter=lambda: next(clock) * 1e-5))
    limited = plan(walls, "bitstar", time_limit=30.0, seed=3, settle=None, soft_limit=0.2)
    assert limited.success
    assert 0.2 <= limited.solve_time_s <= 0.2 + 2 * ompl_planners.SETTLE_POLL_S
    hasty = plan(walls, "bitstar", time_limit=30.0, seed=3, settle=None, soft_limit=1e-5)
    assert hasty.success and hasty.solve_time_s < 30.0


def test_bitstar_settles_only_after_its_first_batch(monkeypatch):
    """Two costly zones 1.2 m apart across the straight line (two groups): BIT* first finds the line through the gap
    and the way round only at the end of its first batch. On a fake clock (each reading 1 ms later) the settle rule
    alone stopped every seed 40 ms after the line (1.13 times the grid planner's cost); it waits for the batch."""
    spec = GridSpec.from_size(0.05, (-1.0, -5.0), (10.0, 10.0))
    x, y = spec.cell_centres()
    zones = np.maximum(*(252 * np.exp(-(np.hypot(x - 3.2, y - c) ** 2) / (2 * 0.5**2)) for c in (0.6, -0.6)))
    problem = PlanningProblem(Costmap2D(spec, zones.astype(np.uint8)), (0.0, 0.0), (7.5, 0.0), RADIUS)
    reference = plan(problem, "grid").cost
    for seed in range(1, 4):
        ticks = itertools.count()
        monkeypatch.setattr(ompl_planners, "time", SimpleNamespace(perf_counter=lambda c=ticks: next(c) * 1e-3))
        result = plan(problem, "bitstar", time_limit=30.0, seed=seed, soft_limit=None)
        assert result.cost <= 1.01 * reference, seed
        assert abs(np.interp(3.2, result.path[:, 0], result.path[:, 1])) > 1.0  # round a zone, not between


# ---- impossible problems and bad input -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("start", "goal", "message"),
    [
        ((-1.0, 2.0), (9.0, 6.0), "start (-1.00, 2.00) is outside the map"),
        ((1.0, 2.0), (9.0, 60.0), "goal (9.00, 60.00) is outside the map"),
        ((3.1, 2.0), (9.0, 6.0), "start (3.10, 2.00) is in collision"),
        ((1.0, 2.0), (6.6, 6.0), "goal (6.60, 6.00) is in collision"),
        ((1.0, 2.0), (6.4, 6.0), "goal (6.40, 6.00) is in collision"),  # inscribed, not lethal
    ],
)
@pytest.mark.parametrize("name", ["grid", "bitstar"])
def test_impossible_endpoints_raise_clear_errors(start, goal, message, name):
    with pytest.raises(PlanningError, match=re.escape(message)):
        plan(PlanningProblem(walled_map(), start, goal, RADIUS), name, time_limit=0.2, seed=1)


def test_an_end_in_collision_says_which_end_and_survives_pickling():
    with pytest.raises(EndpointCollisionError) as caught:
        plan(PlanningProblem(walled_map(), (1.0, 2.0), (6.6, 6.0), RADIUS), "grid")
    copy = pickle.loads(pickle.dumps(caught.value))  # as a sweep's worker process hands it back
    assert copy.end == caught.value.end == "goal" and str(copy) == str(caught.value)
    assert str(copy).startswith("no path: goal (6.60, 6.00) is in collision")


def test_an_end_too_near_for_a_robot_wider_than_the_inflation_says_so():
    """The costmap inflated for a 0.25 m robot, planned for a 0.6 m one: a goal 0.45 m from the wall sits in a cell
    of graded cost, below inscribed, yet the robot's disc reaches the wall; the message said "(cell cost 34)"."""
    with pytest.raises(EndpointCollisionError) as caught:
        plan(PlanningProblem(walled_map(), (1.0, 6.0), (6.05, 6.0), 0.6), "grid")
    message = str(caught.value)
    assert message.startswith(
        "no path: goal (6.05, 6.00) is in collision: an obstacle is within the robot radius 0.60 m"
    )
    assert "is below inscribed: the costmap was inflated for a smaller robot)" in message


@pytest.mark.parametrize("name", ["grid", "rrtstar"])
def test_disconnected_goal_fails_fast_with_reason(name):
    costmap = walled_map()
    x, _ = costmap.spec.cell_centres()
    costmap.costs[(x > 4.9) & (x < 5.1)] = LETHAL  # a wall across the whole map
    with pytest.raises(WalledOffError, match="separate free regions"):
        plan(PlanningProblem(costmap, (1.0, 2.0), (9.0, 6.0), RADIUS), name, time_limit=5.0, seed=1)


def test_budget_exhausted_reports_failure_without_path(walls):
    result = plan(walls, "rrtstar", time_limit=5.0, seed=1, max_iterations=3)
    assert not result.success and len(result.path) == 0
    assert result.message.startswith("rrtstar found no path in ") and result.message.endswith(
        "although the start and the goal are connected on the costmap: a larger time budget may find one, the grid "
        "planner does"
    )  # impossible tasks are refused before planning (check_endpoints): what is left is the budget


def test_planner_names_and_prm_exclusion():
    assert resolve_planner("BITstar") == "bitstar" and resolve_planner("informed-rrtstar") == "informed_rrtstar"
    with pytest.raises(ValueError, match="PRM\\* is not available: .*deadlocks"):
        resolve_planner("prmstar")
    with pytest.raises(ValueError, match="unknown planner 'astar'"):
        resolve_planner("astar")
    for name in (None, 3):  # an AttributeError ('strip') before
        with pytest.raises(ValueError, match=f"planner must be a name, one of: .*; got {name}"):
            resolve_planner(name)  # type: ignore[arg-type]


def test_a_seed_budget_or_sample_count_of_another_kind_is_refused(walls):
    """A seed of 1.5 was cut to 1 and "7" taken; a 'no limit' budget of 1e9 s asked FMT* for 2.5e11 samples, past
    OMPL's unsigned int (a TypeError from pybind11): the budget's samples stop at FMT_MAX_SAMPLES."""
    for seed in (1.5, "7", 0, True):
        with pytest.raises(ValueError, match="plan: seed must be a whole number from 1 to 4294967295"):
            plan(walls, "rrtconnect", seed=seed)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="time_limit must be a positive number of seconds, got '1'"):
        plan(walls, "rrtconnect", time_limit="1")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="plan: max_iterations must be a whole number from 1 to 2147483647"):
        plan(walls, "fmtstar", max_iterations=2**40)
    assert plan(walls, "rrtconnect", seed=7.0, time_limit=0.3).seed == 7
    space = ompl_planners.ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    fmt = ompl_planners.OMPL_PLANNERS["fmtstar"](ompl_planners.ob.SpaceInformation(space), 1e12, None)
    assert fmt.getNumSamples() == ompl_planners.FMT_MAX_SAMPLES


@pytest.mark.parametrize("corner", [(0, 0), (0, 30), (20, 0), (20, 30)])
def test_a_goal_in_a_corner_cell_of_an_empty_map_is_reached(corner: tuple[int, int]) -> None:
    """Border cells are no planner's (the robot would reach past the map); an end cell is, but a corner's only links
    inward are border cells, and a corner goal (a far goal clamped to a rolling window) was 'walled off'."""
    spec = GridSpec(0.1, -5.0, 5.0, 31, 21)
    empty = Costmap2D(spec, np.zeros(spec.shape, np.uint8))
    goal = tuple(spec.cell_to_world(np.array([corner]))[0])
    for name in ("grid", "bitstar"):
        assert plan(PlanningProblem(empty, (-3.5, 6.0), goal, 0.1), name, time_limit=0.5, seed=1).success, name


@pytest.mark.parametrize(
    "bad", [dict(start=(math.nan, 1.0)), dict(robot_radius=-0.1), dict(cost_weight=math.inf), dict(cost_weight=1e308)]
)
def test_bad_problem_values_are_rejected(bad):
    args = dict(costmap=walled_map(), start=(1.0, 2.0), goal=(9.0, 6.0), robot_radius=RADIUS) | bad
    with pytest.raises(PlanningError):
        PlanningProblem(**args)


# ---- repeatability -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(OMPL_PLANNERS))
def test_seed_and_iteration_cap_repeat_exactly(walls, name):
    runs = [plan(walls, name, time_limit=30.0, seed=11, max_iterations=400) for _ in range(2)]
    assert runs[0].success == runs[1].success
    assert runs[0].iterations == runs[1].iterations
    assert np.array_equal(runs[0].raw_path, runs[1].raw_path)
    assert np.array_equal(runs[0].path, runs[1].path)


def test_unseeded_run_reports_the_seed_that_repeats_it(walls):
    first = plan(walls, "rrtstar", time_limit=30.0, max_iterations=200)
    again = plan(walls, "rrtstar", time_limit=30.0, seed=first.seed, max_iterations=200)
    assert first.seed is not None and np.array_equal(first.raw_path, again.raw_path)


@pytest.mark.parametrize(("name", "readings"), [("rrtstar", 300), ("bitstar", 3000)])
def test_a_timed_run_is_replayed_by_its_seed_and_iteration_count(walls, name, readings, monkeypatch):
    """The 0.3 s budget runs out on a fake clock after about ``readings`` clock readings, so where the run stops
    does not depend on the machine's load; the replay runs on the real clock with a generous budget."""
    clock = itertools.count()
    monkeypatch.setattr(ompl_planners, "time", SimpleNamespace(perf_counter=lambda: next(clock) * 0.3 / readings))
    timed = plan(walls, name, time_limit=0.3, seed=21, settle=None, soft_limit=None)  # no early stop: budget runs out
    assert next(clock) > readings  # the fake clock ran the budget out
    monkeypatch.undo()
    replay = plan(walls, name, time_limit=30.0, seed=21, max_iterations=timed.iterations)
    assert timed.success and 0 < timed.iterations <= readings  # one check per reading until the budget is out
    assert np.array_equal(timed.raw_path, replay.raw_path)


@settings(max_examples=12, deadline=None)
@given(
    st.lists(st.tuples(st.floats(0.5, 9.5), st.floats(0.5, 7.5), st.floats(0.1, 0.6)), min_size=3, max_size=12),
    st.tuples(st.floats(0.2, 9.8), st.floats(0.2, 7.8), st.floats(0.2, 9.8), st.floats(0.2, 7.8)),
    st.sampled_from(["grid", "rrtconnect", "bitstar"]),
)
# Start and goal in free regions that touch only at a corner: refused up front, as the grid planner cannot step there.
@example([(1.0, 2.0, 0.5), (1.0, 2.0, 0.5), (1.6875, 0.5, 0.59375)], (0.5, 1.0, 1.0, 1.0), "grid")
def test_random_maps_give_a_valid_path_or_a_clear_refusal(discs, ends, name):
    spec = GridSpec.from_size(0.05, (0.0, 0.0), (10.0, 8.0))
    x, y = spec.cell_centres()
    lethal = np.zeros(spec.shape, bool)
    for cx, cy, r in discs:
        lethal |= np.hypot(x - cx, y - cy) <= r
    costmap = Costmap2D(spec, inflate(lethal, spec))
    problem = PlanningProblem(costmap, ends[:2], ends[2:], RADIUS)
    try:
        result = plan(problem, name, time_limit=30.0, seed=1, max_iterations=CAPS[name])
    except PlanningError as exc:
        assert "in collision" in str(exc) or "separate free regions" in str(exc)
        return
    if result.success:
        assert independent_collisions(costmap, result.path) == 0
    else:
        assert len(result.path) == 0 and result.message


def test_ompl_log_level_is_set_only_while_planning(walls, capfd):
    """No process-global state changes at import; a plan runs quiet and leaves OMPL's log level as it found it."""
    from ompl import util as ou

    code = (
        "from ompl import util as ou; a = ou.getLogLevel(); import planner.ompl_planners; print(a == ou.getLogLevel())"
    )
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout == "True\n"
    before = ou.getLogLevel()
    ou.setLogLevel(ou.LOG_INFO)
    try:
        capfd.readouterr()
        assert plan(walls, "rrtconnect", time_limit=5.0, seed=1, max_iterations=CAPS["rrtconnect"]).success
        assert ou.getLogLevel() == ou.LOG_INFO
        assert capfd.readouterr().out == ""  # OMPL's INFO lines would land on stdout
    finally:
        ou.setLogLevel(before)


def column_wall(origin: float = 0.0) -> Costmap2D:
    """20 x 20 cells at 0.1 m from (origin, origin), lethal column 5."""
    costs = np.zeros((20, 20), np.uint8)
    costs[:, 5] = LETHAL
    return Costmap2D(GridSpec(0.1, origin, origin, 20, 20), costs)


@pytest.mark.parametrize("name", PLANNERS)
def test_a_start_on_a_cell_border_is_plannable_for_every_planner(name: str) -> None:
    # x = 0.3 is the border of columns 2 and 3; (0.3 - 0) * (1 / 0.1) truncates to 3, next to the inscribed column 4,
    # where world_to_cell (and so check_endpoints and the forced start cell) says column 2.
    result = plan(PlanningProblem(column_wall(), (0.3, 1.0), (0.25, 0.25), 0.1), name, time_limit=0.3, seed=1)
    assert result.success, result.message
    assert np.allclose(result.path[0], (0.3, 1.0)) and np.allclose(result.path[-1], (0.25, 0.25))


@pytest.mark.parametrize("origin", [0.0, -1.05])
def test_every_lookup_finds_a_points_cell_as_world_to_cell(origin: float) -> None:
    spec = GridSpec(0.1, origin, origin, 20, 20)
    costs = (np.arange(400).reshape(20, 20) % 200).astype(np.uint8)  # a cost per cell
    costs[::4, ::4] = LETHAL  # plannable: rows and columns 2 (mod 4) only
    field = CostField(PlanningProblem(Costmap2D(spec, costs), (origin + 0.25, origin + 0.25), (origin + 1, origin), 0))
    borders = origin + np.arange(1, 20) / 10  # on cell borders: 0.3 / 0.1 floors to 2, 0.3 * (1 / 0.1) to 3
    xy = np.stack(np.meshgrid(borders, borders), -1).reshape(-1, 2)
    rows, cols = spec.world_to_cell(xy).T
    assert [field.is_plannable(x, y) for x, y in xy] == field.plannable[rows, cols].tolist()
    # A zero-length segment is its own one sample: its plannability reads the point's cell.
    assert field.segments(xy, xy)[1].tolist() == field.plannable[rows, cols].tolist()
    # Segments whose midpoints lie on the borders, priced as the definition prices them (world_to_cell's floor).
    inside = (borders > origin + 0.1) & (borders < origin + 1.9)
    for x, y in itertools.product(borders[inside], borders[inside]):
        for end in ((x + 0.05, y + 0.05), (x + 0.15, y - 0.05)):
            start = (2 * x - end[0], 2 * y - end[1])
            expected = plain_segment_cost(field, spec, *start, *end)
            assert field.segment_cost(*start, *end) == expected
            assert field.segments(np.array([start]), np.array([end]))[0][0] == pytest.approx(expected, rel=1e-12)


def test_both_cost_lookups_cut_a_segment_into_the_same_pieces() -> None:
    # 0.8 - 0.1 is 7.000000000000001 cells of 0.1 m: seven pieces for both lookups, not eight for one of them. Across
    # one column of cost 200, eight midpoints in other cells would make OMPL minimise another J than the one reported.
    costs = np.zeros((20, 20), np.uint8)
    costs[:, 5] = 200
    field = CostField(PlanningProblem(Costmap2D(GridSpec(0.1, 0, 0, 20, 20), costs), (0.15, 1.05), (0.85, 1.05), 0.1))
    tenths = np.arange(1, 19) / 10
    for a, b in itertools.permutations(tenths, 2):
        expected = abs(b - a) * (
            1 + field.weight[10].take(np.arange(round(min(a, b) * 10), round(max(a, b) * 10))).mean()
        )
        assert field.segment_cost(a, 1.05, b, 1.05) == pytest.approx(expected, rel=1e-12)
        assert field.segments(np.array([[a, 1.05]]), np.array([[b, 1.05]]))[0][0] == pytest.approx(expected, rel=1e-12)


def test_an_empty_path_fails_the_check_and_says_why(walls) -> None:
    field = CostField(walls)
    check = check_path(field, np.zeros((0, 2)))
    assert not check.valid and check.samples == 0 and check.describe() == "no samples: the path is empty"
    single = check_path(field, np.array([[1.0, 2.0]]))  # one free point: one free sample
    assert single.valid and single.describe() == "all 1 samples free"
    blocked = check_path(field, np.array([[1.0, 2.0], [4.0, 2.0]]))
    assert not blocked.valid and re.fullmatch(
        r"\d+ of \d+ samples in collision, first at \(\d\.\d{3}, 2\.000\) m", blocked.describe()
    )


@pytest.mark.parametrize("radius", [0.0, 0.05, math.hypot(0.05, 0.05), 0.1, 0.25, 0.3, 1e300])
def test_the_clearance_test_is_the_exact_euclidean_distance_of_cell_centres(radius: float) -> None:
    # The inflation layer's distance transform (OpenCV) against scipy's exact one, at radii on cell distances.
    spec = GridSpec(0.05, -1.0, 2.0, 90, 70)
    lethal = np.random.default_rng(4).random(spec.shape) < 0.004
    costs = np.where(lethal, LETHAL, 0).astype(np.uint8)
    field = CostField(PlanningProblem(Costmap2D(spec, costs), (0.0, 3.0), (1.0, 4.0), radius))
    clearance = ndimage.distance_transform_edt(~lethal) * spec.resolution
    np.testing.assert_array_equal(field.free, clearance > radius)


def test_a_gap_closed_only_by_the_planners_one_cell_margin_is_named_as_such():
    # A 1 m door for a 0.5 m robot on 0.2 m cells: two free cells through it, none plannable (the planners keep one
    # cell more than the radius); the refusal said the robot could not get through, with no word of the margin.
    spec = GridSpec.from_size(0.2, (0.0, 0.0), (8.0, 6.0))
    costs = np.zeros(spec.shape, np.uint8)
    costs[:13, 20:22] = LETHAL  # walls x 4.0-4.4 m, y 0-2.6 m and 3.4-6 m: the door y 2.6-3.4 m
    costs[17:, 20:22] = LETHAL
    problem = PlanningProblem(Costmap2D(spec, costs), (1.0, 3.0), (7.0, 3.0), 0.25)
    field = CostField(problem)
    assert field.free[14:16, 20:22].all() and not field.plannable[:, 20:22].any()
    with pytest.raises(WalledOffError, match=r"only by the planners' margin of one cell \(0.2 m\) beyond the robot"):
        plan(problem, "grid")
    costs[17:, 20:22] = 0  # open: the message of a true wall says nothing of the margin
    costs[:, 20:22] = LETHAL
    with pytest.raises(WalledOffError, match=r"for a robot of radius 0.25 m\)$"):
        plan(PlanningProblem(Costmap2D(spec, costs), (1.0, 3.0), (7.0, 3.0), 0.25), "grid")
