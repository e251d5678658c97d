"""``sid plan``: one plan of a scenario's robot task (through ``sid.experiments.harness``), written as ``path.json``
and ``plan.png``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from planner.facade import DEFAULT_PLANNER
from planner.problem import DEFAULT_COST_WEIGHT
from sid.experiments.harness import Comparison, compare_with_without, prepare
from sid.experiments.plan_pictures import plan_picture
from sid.scenario.loader import Scenario

__all__ = ["path_record", "plan_scenario", "write_plan"]


def plan_scenario(
    scenario: Scenario,
    social: bool = True,
    planner: str = DEFAULT_PLANNER,
    time_limit: float = 0.5,
    seed: int | None = None,
    max_iterations: int | None = None,
    cost_weight: float = DEFAULT_COST_WEIGHT,
) -> Comparison:
    """Plan the scenario's task on its costmap with (or without) the social layer: a comparison of one run.

    Raises ``planner.problem.PlanningError`` for an impossible task and ValueError for an unknown planner or bad
    budget.
    """
    mode = "with" if social else "without"
    return compare_with_without(prepare(scenario, cost_weight), planner, time_limit, seed, max_iterations, (mode,))


def path_record(comparison: Comparison) -> dict[str, Any]:
    """The JSON record of a one-run comparison: every metric at the top level, plus the waypoints (world frame)."""
    (run,) = comparison.runs.values()
    robot = comparison.task.scenario.robot
    return run.metrics | {
        "scenario": run.scenario,
        "social_layer": run.social_layer,
        "frame": "world (REP-103: x forward, y left), metres",
        "start": list(robot.start[:2]),
        "goal": list(robot.goal[:2]),
        "waypoints": np.round(run.result.path, 4).tolist(),
    }


def write_plan(comparison: Comparison, out_dir: str | Path) -> dict[str, Path]:
    """Write ``path.json`` and ``plan.png`` into ``out_dir`` (created if missing); returns their paths."""
    (run,) = comparison.runs.values()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {"path": out / "path.json", "picture": out / "plan.png"}
    paths["path"].write_text(json.dumps(path_record(comparison), indent=2, allow_nan=False) + "\n")
    costmap = "the costmap with the social layer" if run.social_layer else "the costmap without the social layer"
    title = f"{run.scenario}: {run.planner} on {costmap}"
    seed = "" if run.result.seed is None else f", seed {run.result.seed}"
    if not cv2.imwrite(str(paths["picture"]), plan_picture(comparison, title, run.result.message + seed)):
        raise OSError(f"could not write {paths['picture']}")
    return paths
