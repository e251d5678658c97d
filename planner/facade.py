"""The planning facade: ``plan(problem, planner=NAME, ...)`` over OMPL's planners and the grid planner.

Every planner solves the same problem (``planner.problem``): a disc robot on a costmap, states checked against the
precomputed plannable mask, motions checked at the costmap resolution, cost J = integral of (1 + w c / 252) ds.
Each returned path has been smoothed (``planner.smoothing``, never raising J) and checked at every quarter-cell
sample against the exact free mask; a path that fails that check is never returned. Seeds and iteration caps:
see ``planner.ompl_planners``.
"""

from __future__ import annotations

import math
import secrets
import time
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from costmap.grid import INSCRIBED, LETHAL, NO_INFORMATION
from planner.grid_planner import grid_search
from planner.ompl_planners import OMPL_PLANNERS, seed_ompl, solve_ompl
from planner.problem import CostField, EndpointCollisionError, PlanningError, PlanningProblem, WalledOffError
from planner.smoothing import smooth
from planner.validity import check_path
from sid.checks import check_whole, is_real
from sid.errors import InputError

__all__ = [
    "DEFAULT_PLANNER",
    "DEFAULT_SETTLE_S",
    "DEFAULT_SOFT_LIMIT_S",
    "MAX_SEED",
    "PLANNERS",
    "PlanResult",
    "UNAVAILABLE",
    "check_endpoints",
    "free_regions",
    "plan",
    "resolve_planner",
]

PLANNERS: tuple[str, ...] = (*OMPL_PLANNERS, "grid")
"""Every planner ``plan`` offers: OMPL's (``planner.ompl_planners``) and the grid planner."""
DEFAULT_PLANNER = "bitstar"
DEFAULT_SETTLE_S = 0.04
"""``plan``'s default ``settle``: an anytime planner stops once its cost has not improved for this long (s).
Chosen over the navigation study's tasks (docs/benchmarks.md, "Planning: when BIT* stops")."""
DEFAULT_SOFT_LIMIT_S = 0.10
"""``plan``'s default ``soft_limit``: an anytime planner that has a path stops after this long (s) even if its cost
still falls, so that a plan (with the lookups, smoothing and the final check) keeps to the time the navigation study
allows it without costing more than the seeds' own spread (docs/benchmarks.md, "Planning: when BIT* stops")."""
MAX_SEED = 2**32 - 1
"""The largest seed ``plan`` takes: OMPL's seed is a ``std::uint_fast32_t``, 32 bits wide on some platforms."""
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
    if not isinstance(name, str):
        raise InputError(f"planner must be a name, one of: {', '.join(PLANNERS)}; got {name!r}")
    key = name.strip().lower().replace("-", "_")
    if key in UNAVAILABLE:
        raise InputError(UNAVAILABLE[key])
    if key not in PLANNERS:
        raise InputError(f"unknown planner {name!r}; choose one of: {', '.join(PLANNERS)}")
    return key


def _collision(cost: int, problem: PlanningProblem) -> str:
    """Why a robot centre in a cell of ``cost`` is not free, in words."""
    radius = f"{problem.robot_radius:.2f} m"
    if cost == LETHAL:
        return f"it lies inside an obstacle (cell cost {LETHAL}, lethal)"
    if cost == INSCRIBED:
        return f"an obstacle is within the robot radius {radius} (cell cost {INSCRIBED}, inscribed)"
    if cost == NO_INFORMATION:
        return f"it lies in unknown space (cell cost {NO_INFORMATION})"
    # Below INSCRIBED yet not free: the costmap was inflated for a smaller robot; the planner checks this one's disc.
    return (
        f"an obstacle is within the robot radius {radius} (the cell's cost, {cost}, is below inscribed: the costmap "
        "was inflated for a smaller robot)"
    )


def free_regions(field: CostField) -> np.ndarray:
    """The connected regions of ``field.plannable``: an int array of the grid's shape, 0 on cells not plannable
    and one label per region elsewhere. 4-connected: a diagonal step between plannable cells needs the two cells
    beside it plannable too (no corner cutting, as in the grid planner), so cells that touch only at a corner are
    not connected."""
    labels, _ = ndimage.label(field.plannable)
    return np.asarray(labels)


def check_endpoints(field: CostField) -> None:
    """Raise NoPathError, its message starting "no path: " and naming the reason, when the start or goal lies in
    collision (EndpointCollisionError) or the two cannot be connected (WalledOffError); PlanningError "... is outside
    the map"."""
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
            message = f"no path: {name} ({x:.2f}, {y:.2f}) is in collision: {_collision(cost, problem)}"
            raise EndpointCollisionError(message, name)
        cells.append(cell)
    labels = free_regions(field)
    (sr, sc), (gr, gc) = cells
    if labels[sr, sc] != labels[gr, gc]:
        free, _ = ndimage.label(field.free)  # free cells, without the planner's margin of one cell
        margin = (
            f"; only by the planners' margin of one cell ({spec.resolution:g} m) beyond the robot's radius: a finer "
            "costmap resolution narrows it"
            if free[sr, sc] == free[gr, gc]
            else ""
        )
        raise WalledOffError(
            "no path: the start and the goal lie in separate free regions of the costmap (walled off from each "
            f"other for a robot of radius {problem.robot_radius:.2f} m{margin})"
        )


def plan(
    problem: PlanningProblem,
    planner: str = DEFAULT_PLANNER,
    time_limit: float = 0.5,
    seed: int | None = None,
    max_iterations: int | None = None,
    simplify: bool = True,
    settle: float | None = DEFAULT_SETTLE_S,
    soft_limit: float | None = DEFAULT_SOFT_LIMIT_S,
) -> PlanResult:
    """Plan ``problem`` with the named planner (``PLANNERS``; ``"grid"`` is the Dijkstra + any-angle planner).

    time_limit: seconds for the planner's solve(), at most; seed / max_iterations: see the module docstring (the grid
    planner is deterministic and ignores them). settle, soft_limit: BIT* stops earlier once it has a path, when the
    path's cost has not improved for ``settle`` seconds or after ``soft_limit`` seconds of solving
    (``planner.ompl_planners.solve_ompl``; ``DEFAULT_SETTLE_S``, ``DEFAULT_SOFT_LIMIT_S``); without a path it goes
    on to ``time_limit``. None (both), or a ``max_iterations`` cap (whose runs must repeat exactly), uses the whole
    ``time_limit``. Raises PlanningError when the start or goal is outside the map, in collision or unreachable,
    and ValueError for an unknown planner or a bad budget; a planner that finds no path in its budget gives
    ``success=False`` with the reason in ``message``.
    """
    name = resolve_planner(planner)
    if not (is_real(time_limit) and math.isfinite(time_limit) and time_limit > 0):
        raise InputError(f"time_limit must be a positive number of seconds, got {time_limit!r}")
    if max_iterations is not None:  # OMPL takes an unsigned int
        max_iterations = check_whole("plan", "max_iterations", max_iterations, low=1, high=2**31 - 1)
    for option, value in (("settle", settle), ("soft_limit", soft_limit)):
        if value is not None and not (is_real(value) and math.isfinite(value) and value > 0):
            raise InputError(f"{option} must be a positive number of seconds or None, got {value!r}")
    t0 = time.perf_counter()
    if name != "grid":
        # a whole number (1.5 was cut to 1, "7" taken), and not 0, which OMPL ignores
        if seed is None:
            seed = secrets.randbelow(2**31 - 1) + 1
        seed = check_whole("plan", "seed", seed, low=1, high=MAX_SEED)
        seed_ompl(seed)
    else:
        seed = None
    field = CostField(problem)
    check_endpoints(field)

    raw: np.ndarray | None
    if name == "grid":
        t_solve = time.perf_counter()
        raw, iterations, solve_time = grid_search(field), 0, time.perf_counter() - t_solve
    else:
        if max_iterations is not None:  # a capped run must repeat exactly: no stop on the clock but time_limit
            settle = soft_limit = None
        raw, iterations, solve_time = solve_ompl(field, name, time_limit, max_iterations, settle, soft_limit)
    raw_cost = math.inf if raw is None else field.path_cost(raw)
    result = PlanResult(name, False, np.zeros((0, 2)), math.inf, 0.0, 0.0, solve_time, raw_cost, iterations, seed, "")
    if raw is None:
        samples = " (FMT*'s samples grow with it)" if name == "fmtstar" else ""
        result.message = (
            f"{name} found no path in {solve_time:.2f} s ({iterations} termination checks), although the start and "
            f"the goal are connected on the costmap: a larger time budget{samples} may find one, the grid planner "
            "does"
        )
        result.planning_time_s = time.perf_counter() - t0
        return result
    result.raw_path = path = raw
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
