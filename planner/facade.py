"""The planning facade: ``plan(problem, planner=NAME, ...)`` over OMPL's planners and the grid planner.

Every planner solves the same problem (``planner.problem``): a disc robot on a costmap, states checked against the
precomputed plannable mask, motions checked at the costmap resolution, cost J = integral of (1 + w c / 252) ds.
Each returned path has been smoothed (``planner.smoothing``, never raising J) and checked at every quarter-cell
sample against the exact free mask; a path that fails that check is never returned.

Repeatability: ``seed`` seeds OMPL's random numbers before anything of the problem is built, and ``max_iterations``
caps the number of times the planner checks its termination condition (about once per iteration; BIT* checks it
once per edge it processes; for FMT* it is the number of samples). A run with the same seed that stops on the
cap, not on ``time_limit``, is repeated exactly; a run without a seed draws one and reports it in
``PlanResult.seed``.

PRM* is not offered: it grows its roadmap in a worker thread, and with this cost objective (a Python ``motionCost``)
ompl 2.0.1's bindings deadlock there (measured: a 0.5 s solve had not returned after 10 s). With OMPL's C++ path-length
objective it does run, but then it plans a different problem (the social costs ignored), so it would not be
comparable. No other thread runs Python here: every planner below calls back into Python from ``solve()``'s thread.
"""

from __future__ import annotations

import math
import secrets
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou
from scipy import ndimage

from planner.grid_planner import grid_search
from planner.objective import CostmapObjective
from planner.problem import CostField, PlanningError, PlanningProblem
from planner.smoothing import smooth
from planner.validity import check_path, state_validity_checker

ou.setLogLevel(ou.LOG_WARN)  # the default level prints OMPL's debug messages to stdout

FMT_SAMPLES_PER_SECOND = 250
"""FMT* is not anytime: it plans on a fixed sample set and returns nothing if stopped early. With this objective it
takes 1.2-1.6 ms per sample on the demo scenario (measured: 100 samples 0.14 s, 300 0.49 s, 600 0.74 s), so its
sample count follows the time budget with a margin of about two for a busy machine, or equals ``max_iterations``
when that is given."""


def _fmt(si: ob.SpaceInformation, time_limit: float, max_iterations: int | None) -> ob.Planner:
    planner = og.FMT(si)
    samples = max_iterations if max_iterations is not None else int(FMT_SAMPLES_PER_SECOND * time_limit)
    planner.setNumSamples(max(50, samples))
    return planner


OMPL_PLANNERS: dict[str, Callable[[ob.SpaceInformation, float, int | None], ob.Planner]] = {
    "rrtstar": lambda si, *_: og.RRTstar(si),
    "informed_rrtstar": lambda si, *_: og.InformedRRTstar(si),
    "bitstar": lambda si, *_: og.BITstar(si),
    "rrtconnect": lambda si, *_: og.RRTConnect(si),
    "fmtstar": _fmt,
}
"""Planner factories (space information, time budget in s, iteration cap or None) by name."""
PLANNERS: tuple[str, ...] = (*OMPL_PLANNERS, "grid")
DEFAULT_PLANNER = "bitstar"
UNAVAILABLE: dict[str, str] = {
    "prmstar": (
        "PRM* is not available: it grows its roadmap in a worker thread that calls the Python cost objective, "
        "which deadlocks in ompl 2.0.1's Python bindings (and with OMPL's C++ length objective it would ignore "
        "the social costs); use bitstar, informed_rrtstar, rrtstar, fmtstar, rrtconnect or grid"
    ),
}


@dataclass
class PlanResult:
    """The outcome of one plan. ``path`` is (N, 2) in the world frame (metres), empty when ``success`` is False.

    cost: J of the returned path; raw_cost: J of the planner's own path before smoothing; planning_time_s covers
    building the lookups, solving, smoothing and the final check; solve_time_s the planner's solve() alone.
    """

    planner: str
    success: bool
    path: np.ndarray
    cost: float
    length_m: float
    planning_time_s: float
    solve_time_s: float
    raw_cost: float
    iterations: int  # termination checks passed; ``max_iterations=iterations`` with ``seed`` repeats the run
    seed: int | None
    message: str
    raw_path: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)), repr=False)


def resolve_planner(name: str) -> str:
    """The registry name for ``name`` (case-insensitive), or a ValueError listing the choices."""
    key = name.strip().lower().replace("-", "_")
    if key in UNAVAILABLE:
        raise ValueError(UNAVAILABLE[key])
    if key not in PLANNERS:
        raise ValueError(f"unknown planner {name!r}; choose one of: {', '.join(PLANNERS)}")
    return key


def check_endpoints(field: CostField) -> None:
    """Raise PlanningError naming the reason when the start or goal cannot be used, or cannot be connected."""
    problem, spec = field.problem, field.spec
    x0, y0 = spec.origin_x, spec.origin_y
    x1, y1 = x0 + spec.size_m[0], y0 + spec.size_m[1]
    cells = []
    for name, (x, y) in (("start", problem.start), ("goal", problem.goal)):
        if not spec.contains(np.array([x, y]))[0]:
            raise PlanningError(
                f"{name} ({x:.2f}, {y:.2f}) is outside the map, which covers x {x0:.2f}..{x1:.2f} m, "
                f"y {y0:.2f}..{y1:.2f} m"
            )
        cell = spec.world_to_cell(np.array([x, y]))[0]
        if not field.free[cell[0], cell[1]]:
            cost = int(problem.costmap.costs[cell[0], cell[1]])
            raise PlanningError(
                f"{name} ({x:.2f}, {y:.2f}) is in collision: cell cost {cost} (253 inscribed, 254 lethal, 255 "
                f"unknown) or an obstacle within the robot radius {problem.robot_radius:.2f} m"
            )
        cells.append(cell)
    labels, _ = ndimage.label(field.plannable, structure=np.ones((3, 3), bool))
    (sr, sc), (gr, gc) = cells
    if labels[sr, sc] != labels[gr, gc]:
        raise PlanningError(
            "no collision-free path: the start and the goal lie in separate free regions of the costmap "
            f"(for a robot of radius {problem.robot_radius:.2f} m)"
        )


def _seed_ompl(seed: int) -> None:
    # OMPL logs an error when reseeding after its first random number; reseeding still makes every generator
    # created afterwards deterministic (measured), which is all a plan needs since it creates its own.
    level = ou.getLogLevel()
    ou.setLogLevel(ou.LOG_NONE)
    ou.RNG.setSeed(seed)
    ou.setLogLevel(level)


def _solve_ompl(
    field: CostField, name: str, time_limit: float, max_iterations: int | None
) -> tuple[np.ndarray | None, int, float]:
    """Run one OMPL planner; (path or None, termination checks, solve seconds)."""
    problem, spec = field.problem, field.spec
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0, spec.origin_x)
    bounds.setHigh(0, spec.origin_x + spec.size_m[0])
    bounds.setLow(1, spec.origin_y)
    bounds.setHigh(1, spec.origin_y + spec.size_m[1])
    space.setBounds(bounds)
    space.setLongestValidSegmentFraction(spec.resolution / space.getMaximumExtent())
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(state_validity_checker(field))
    si.setup()
    pdef = ob.ProblemDefinition(si)
    start, goal = space.allocState(), space.allocState()
    start[0], start[1] = problem.start
    goal[0], goal[1] = problem.goal
    pdef.setStartAndGoalStates(start, goal)
    objective = CostmapObjective(si, field)
    pdef.setOptimizationObjective(objective)
    planner = OMPL_PLANNERS[name](si, time_limit, max_iterations)
    planner.setProblemDefinition(pdef)
    planner.setup()

    # ``checks`` counts the termination checks answered "go on", so a rerun capped at that count stops at the same
    # point. FMT* stops by itself after its samples, which ``max_iterations`` sets (see FMT_SAMPLES_PER_SECOND).
    checks = 0
    cap = math.inf if max_iterations is None or name == "fmtstar" else max_iterations
    deadline = time.perf_counter() + time_limit

    def stop() -> bool:
        nonlocal checks
        if checks >= cap or time.perf_counter() > deadline:
            return True
        checks += 1
        return False

    t0 = time.perf_counter()
    planner.solve(ob.PlannerTerminationCondition(stop))
    solve_time = time.perf_counter() - t0
    path = None
    if pdef.hasExactSolution():
        states = pdef.getSolutionPath().getStates()
        path = np.array([(s[0], s[1]) for s in states], dtype=float)
    planner.clear()
    pdef.clearSolutionPaths()
    return path, checks, solve_time


def plan(
    problem: PlanningProblem,
    planner: str = DEFAULT_PLANNER,
    time_limit: float = 0.5,
    seed: int | None = None,
    max_iterations: int | None = None,
    simplify: bool = True,
) -> PlanResult:
    """Plan ``problem`` with the named planner (``PLANNERS``; ``"grid"`` is the Dijkstra + any-angle planner).

    time_limit: seconds for the planner's solve(); seed / max_iterations: see the module docstring (the grid
    planner is deterministic and ignores them). Raises PlanningError when the start or goal is outside the map,
    in collision or unreachable, and ValueError for an unknown planner or a bad budget; a planner that finds no
    path in its budget gives ``success=False`` with the reason in ``message``.
    """
    name = resolve_planner(planner)
    if not (math.isfinite(time_limit) and time_limit > 0):
        raise ValueError(f"time_limit must be a positive number of seconds, got {time_limit}")
    if max_iterations is not None and max_iterations < 1:
        raise ValueError(f"max_iterations must be at least 1, got {max_iterations}")
    t0 = time.perf_counter()
    if name != "grid":
        seed = secrets.randbelow(2**31 - 1) + 1 if seed is None else int(seed)
        if seed <= 0:
            raise ValueError(f"seed must be a positive integer (OMPL ignores 0), got {seed}")
        _seed_ompl(seed)
    else:
        seed = None
    field = CostField(problem)
    check_endpoints(field)

    if name == "grid":
        t_solve = time.perf_counter()
        raw, iterations, solve_time = grid_search(field), 0, time.perf_counter() - t_solve
    else:
        raw, iterations, solve_time = _solve_ompl(field, name, time_limit, max_iterations)
    path = raw
    raw_cost = math.inf if path is None else field.path_cost(raw)
    result = PlanResult(name, False, np.zeros((0, 2)), math.inf, 0.0, 0.0, solve_time, raw_cost, iterations, seed, "")
    if path is None:
        result.message = f"{name} found no path in {solve_time:.2f} s ({iterations} termination checks)"
        result.planning_time_s = time.perf_counter() - t0
        return result
    result.raw_path = raw
    if simplify:
        path = smooth(field, raw)
    check = check_path(field, path)
    if not check.valid and simplify:
        path, check = raw, check_path(field, raw)
    result.planning_time_s = time.perf_counter() - t0
    if not check.valid:
        result.message = f"{name}'s path failed the final collision check ({check.describe()}); not returned"
        return result
    result.success, result.path, result.cost = True, path, field.path_cost(path)
    result.length_m = float(np.hypot(*np.diff(path, axis=0).T).sum())
    result.message = f"{name}: {result.length_m:.2f} m, cost {result.cost:.2f}, {check.describe()}"
    return result
