"""The planner benchmark (``sid bench``'s ``plan/*`` stages): one planner on the demo scenario with the social layer,
as ``sid demo`` plans it, with OMPL seeds 1..K at the target budget, its cost against the grid planner's
(``sid.experiments.harness``).

The project's target: a planner's worst cost within 3 % of the grid reference in 0.5 s, on every seed
(``meets_target``).
"""

from __future__ import annotations

from sid.experiments.demo import demo_scenario
from sid.experiments.harness import Run, Task, prepare, run_matrix, summarise

__all__ = ["TARGET_BUDGET_S", "TARGET_COST_RATIO", "bench_planner", "meets_target", "planner_task"]

TARGET_BUDGET_S = 0.5
TARGET_COST_RATIO = 1.03


def planner_task() -> Task:
    """The demo scenario ready to plan (``sid.experiments.harness.prepare``)."""
    return prepare(demo_scenario())


def bench_planner(task: Task, planner: str, runs: int, budget: float = TARGET_BUDGET_S) -> tuple[list[Run], dict]:
    """``planner`` on ``task`` with the social layer, OMPL seeds 1..``runs`` (grid: once), ``budget`` seconds each:
    the runs and their ``harness.summarise`` row."""
    planned = run_matrix([task], [planner], runs, (budget,), modes=("with",))
    (row,) = summarise([run.record() for run in planned], ("time_limit_s", "planner"))
    return planned, row


def meets_target(row: dict) -> bool:
    """Whether a ``harness.summarise`` row meets the target: a budget of at most 0.5 s, every run successful, and
    the worst cost ratio to the grid reference at most 1.03."""
    worst = row["worst_cost_ratio"]
    return (
        row["time_limit_s"] <= TARGET_BUDGET_S
        and row["success_rate"] == 1.0
        and worst is not None
        and worst <= TARGET_COST_RATIO
    )
