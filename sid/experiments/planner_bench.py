"""Planner benchmark on the demo scenario with the social layer: median planning time and cost ratio to the grid
reference per planner and time budget (``sid bench`` may call ``bench_planners``; it is not a timed test).

The project's target: the default planner's cost within 3 % of the grid reference in 0.5 s with the social
objective (``meets_target``).
"""

from __future__ import annotations

from collections.abc import Sequence

from planner.facade import DEFAULT_PLANNER, PLANNERS
from sid.experiments.compare import Progress, format_summary, run_matrix, summarise
from sid.experiments.demo import demo_scenario
from sid.scenario.loader import Scenario

TARGET_BUDGET_S = 0.5
TARGET_COST_RATIO = 1.03


def bench_planners(
    budgets: Sequence[float] = (0.5, 1.0),
    runs: int = 5,
    planners: Sequence[str] = PLANNERS,
    scenario: Scenario | None = None,
    progress: Progress | None = None,
) -> list[dict]:
    """``sid.experiments.compare.summarise`` rows (one per budget x planner) on ``scenario`` (default: the demo's), with
    the social layer, seeds 1..``runs``."""
    runs_ = run_matrix([scenario or demo_scenario()], planners, runs, budgets, (True,), progress=progress)
    return summarise(runs_)


def meets_target(rows: Sequence[dict], planner: str = DEFAULT_PLANNER) -> bool | None:
    """Whether ``planner``'s worst cost ratio at the 0.5 s budget is within 3 % of the reference (None: not run)."""
    for row in rows:
        if row["planner"] == planner and row["time_limit_s"] == TARGET_BUDGET_S:
            worst = row["worst_cost_ratio"]
            return worst is not None and row["success_rate"] == 1.0 and worst <= TARGET_COST_RATIO
    return None


__all__ = ["bench_planners", "format_summary", "meets_target"]
