"""OMPL's planners on a ``planner.problem`` costmap problem: the registry, seeding and one solve.

States are checked against the problem's precomputed plannable mask, motions at the costmap resolution; the
objective is ``planner.objective.CostmapObjective``. ``planner.facade.plan`` is the entry point that calls these.

Repeatability: ``seed`` seeds OMPL's random numbers before anything of the problem is built, and ``max_iterations``
caps the number of times the planner checks its termination condition (about once per iteration; BIT* checks it
once per edge it processes; for FMT* it is the number of samples). A run with the same seed that stops on the
cap, not on ``time_limit``, is repeated exactly; a run without a seed draws one and reports it in
``PlanResult.seed``.

PRM* is not offered: it grows its roadmap in a worker thread, and with this cost objective (a Python ``motionCost``)
ompl 2.0.1's bindings deadlock there (docs/parameters.md). With OMPL's C++ path-length
objective it does run, but then it plans a different problem (the social costs ignored), so it would not be
comparable. No other thread runs Python here: every planner below calls back into Python from ``solve()``'s thread.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable, Iterator

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from planner.objective import CostmapObjective
from planner.problem import CostField
from planner.validity import state_validity_checker

__all__ = [
    "FMT_MAX_SAMPLES",
    "FMT_SAMPLES_PER_SECOND",
    "OMPL_PLANNERS",
    "SETTLE_GAIN",
    "SETTLE_POLL_S",
    "SETTLING_PLANNERS",
    "seed_ompl",
    "solve_ompl",
]

FMT_SAMPLES_PER_SECOND = 250
"""Samples of FMT* per second of time budget. FMT* is not anytime: it plans on a fixed sample set and returns nothing
if stopped early, so its sample count follows the time budget, at a rate below the one it reaches on the demo
scenario (a margin for a slower or loaded machine; the rates in docs/parameters.md), up to ``FMT_MAX_SAMPLES``, or
equals ``max_iterations`` when that is given."""
FMT_MAX_SAMPLES = 25_000
"""The most samples a time budget gives FMT* (100 s of it at ``FMT_SAMPLES_PER_SECOND``): a 'no limit' budget of 1e9 s
asked OMPL for 2.5e11, past its unsigned int (a TypeError from setNumSamples), and 1e7 s for 2.5e9, which it was
still drawing a minute later."""


SETTLING_PLANNERS = ("bitstar",)
"""The planners ``solve_ompl`` may stop early (``settle``, ``soft_limit``). BIT*'s cost drops in a few steps and
then flattens. RRT* and Informed RRT* improve in long plateaus: stopped early, Informed RRT* kept paths through group
zones (docs/benchmarks.md, "Planning: when BIT* stops"), so they keep their whole budget."""
SETTLE_GAIN = 0.001
"""A relative cost decrease smaller than this (0.1 %) does not count as an improvement for ``solve_ompl``'s settle."""
SETTLE_POLL_S = 0.002
"""How often (s) ``solve_ompl``'s termination check reads the planner's best cost when settling."""


def _fmt(si: ob.SpaceInformation, time_limit: float, max_iterations: int | None) -> ob.Planner:
    planner = og.FMT(si)
    budget = int(min(FMT_SAMPLES_PER_SECOND * time_limit, FMT_MAX_SAMPLES))
    samples = max_iterations if max_iterations is not None else budget
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


@contextlib.contextmanager
def _ompl_log_level(level: int) -> Iterator[None]:
    """OMPL's process-wide log level set to ``level`` for the block, then restored: planning sets it only while it
    runs (OMPL's default prints its debug messages to stdout), so importing the planner changes nothing."""
    before = ou.getLogLevel()
    ou.setLogLevel(level)
    try:
        yield
    finally:
        ou.setLogLevel(before)


def seed_ompl(seed: int) -> None:
    """Seed OMPL's random number generator, which is process-wide (``ompl::RNG::setSeed``, OMPL's only way to seed):
    every generator OMPL creates afterwards, in any planner of the process, draws from it."""
    # OMPL logs an error when reseeding after its first random number; reseeding still makes every generator
    # created afterwards deterministic (the seed tests in tests/planner check it), which is all a plan needs since
    # it creates its own.
    with _ompl_log_level(ou.LOG_NONE):
        ou.RNG.setSeed(seed)


@_ompl_log_level(ou.LOG_WARN)  # OMPL's set-up and solve log at INFO level by default, on stdout
def solve_ompl(
    field: CostField,
    name: str,
    time_limit: float,
    max_iterations: int | None,
    settle: float | None = None,
    soft_limit: float | None = None,
) -> tuple[np.ndarray | None, int, float]:
    """Run one OMPL planner; (path or None, termination checks, solve seconds).

    For the planners of ``SETTLING_PLANNERS``, once a solution exists: settle stops the solve when its cost has not
    fallen by more than ``SETTLE_GAIN`` over the last ``settle`` seconds (from BIT*'s second batch on: in the
    first, the straight line through two groups can hold for longer than ``settle`` before the way round them
    appears at the batch's end), soft_limit when ``soft_limit`` seconds of solving have passed (``time_limit`` stays
    the cap while there is no solution). The cost is polled every ``SETTLE_POLL_S`` seconds of the termination
    checks. None (both), and every other planner: the whole ``time_limit``.
    """
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
    begin = time.perf_counter()
    deadline = begin + time_limit
    early = name in SETTLING_PLANNERS and (settle is not None or soft_limit is not None)
    best_cost = planner.bestCost if early else None
    patience = math.inf if settle is None else settle
    soft_deadline = math.inf if soft_limit is None else begin + soft_limit
    settled_cost, settled_at, next_poll = math.inf, begin, 0.0

    def stop() -> bool:
        nonlocal checks, settled_cost, settled_at, next_poll
        now = time.perf_counter()
        if checks >= cap or now > deadline:
            return True
        if best_cost is not None and now >= next_poll:
            next_poll = now + SETTLE_POLL_S
            cost = best_cost().value()
            if cost < settled_cost * (1.0 - SETTLE_GAIN):
                settled_cost, settled_at = cost, now
            # Settling waits for the end of BIT*'s first batch (``numBatches`` counts the batches started): before
            # it BIT* has only tried the straight line and the samples of that batch, and a cost flat for
            # ``settle`` seconds there says nothing about the routes the batch has yet to connect.
            settled = now - settled_at > patience and planner.numBatches() > 1
            if math.isfinite(cost) and (settled or now > soft_deadline):
                return True
        checks += 1
        return False

    planner.solve(ob.PlannerTerminationCondition(stop))
    solve_time = time.perf_counter() - begin  # from the instant the budget counts from: a run to its deadline took it
    path = None
    if pdef.hasExactSolution():
        states = pdef.getSolutionPath().getStates()
        path = np.array([(s[0], s[1]) for s in states], dtype=float)
    planner.clear()
    pdef.clearSolutionPaths()
    return path, checks, solve_time
