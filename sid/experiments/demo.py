"""The project's main result: plan the same task without and with group recognition, and show the difference.

``DEMO_SCENARIO`` is the built-in task ``sid demo`` runs: a corridor, a robot, and its goal behind three people in
conversation, with a fourth person standing alone. ``run_demo`` plans it (or any scenario) through
``sid.experiments.harness.compare_with_without`` with a fixed seed and iteration cap, and writes the picture and the
metrics.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

from planner.facade import DEFAULT_PLANNER
from planner.problem import DEFAULT_COST_WEIGHT
from sid.experiments.harness import LABELS, Comparison, Run, compare_with_without, prepare
from sid.experiments.plan_pictures import plan_picture
from sid.scenario.loader import Scenario, scenario_from_dict

__all__ = ["DEMO_ITERATIONS", "DEMO_SCENARIO", "DEMO_SEED", "comparison_picture", "demo_scenario", "run_demo"]


def _circle(ids: tuple[int, ...], centre: tuple[float, float], radius: float, angles_deg: tuple[float, ...]) -> list:
    """People on a circle around ``centre``, each facing it (scenario-file dicts, world frame)."""
    people = []
    for pid, angle in zip(ids, angles_deg, strict=True):
        a = math.radians(angle)
        x, y = centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a)
        people.append({"id": pid, "x": round(x, 3), "y": round(y, 3), "theta": round(a + math.pi, 4)})
    return people


DEMO_SCENARIO: dict = {
    "name": "demo: goal behind a conversation",
    "map": {"resolution": 0.05, "origin": [-1.0, -3.5], "size": [11.0, 7.0]},
    "obstacles": [
        {"type": "segment", "points": [[-1.0, 3.0], [10.0, 3.0]]},
        {"type": "segment", "points": [[-1.0, -3.0], [10.0, -3.0]]},
        {"type": "box", "min": [1.5, 1.4], "max": [2.3, 3.0]},
        {"type": "box", "min": [6.8, -3.0], "max": [7.6, -1.6]},
    ],
    # Three people 1.56 m apart (a triangle of radius 0.9 m) talking, facing their o-space centre (4.5, 0); one
    # more standing alone by the far wall.
    "people": [
        *_circle((1, 2, 3), (4.5, 0.0), 0.9, (90.0, 210.0, 330.0)),
        {"id": 4, "x": 7.6, "y": 1.5, "theta": -2.6},
    ],
    "robot": {"start": [0.0, 0.0, 0.0], "goal": [9.0, 0.0, 0.0], "radius": 0.25},
}
"""The built-in scenario, in the scenario-file format (``sid.scenario.loader``; world frame, metres, radians)."""

DEMO_SEED = 1
DEMO_ITERATIONS = 20000
"""The demo's planner budget: a fixed seed and iteration cap make every run draw the same paths; the time limit
(``sid demo --time``) only guards against a machine too slow to reach the cap (docs/parameters.md)."""


def demo_scenario() -> Scenario:
    return scenario_from_dict(DEMO_SCENARIO, default_name="demo")


def comparison_picture(comparison: Comparison) -> np.ndarray:
    """BGR image of a with/without comparison: both paths over the social costmap, with the metrics table."""
    planner, seed = comparison.runs["with"].planner, comparison.runs["with"].result.seed
    return plan_picture(
        comparison,
        "Without group recognition the robot cuts through the conversation; with it, it goes around",
        f"{comparison.task.scenario.name}. Colours: the costmap with the social layer. Planner {planner}, "
        f"seed {seed}. The dashed path was planned on the costmap without the social layer.",
    )


def run_demo(
    out_dir: str | Path,
    scenario: Scenario | None = None,
    planner: str = DEFAULT_PLANNER,
    time_limit: float = 5.0,
    seed: int | None = DEMO_SEED,
    max_iterations: int | None = DEMO_ITERATIONS,
    cost_weight: float = DEFAULT_COST_WEIGHT,
    progress: Callable[[str], None] | None = None,
) -> Comparison:
    """Run the comparison (built-in scenario by default) and write ``comparison.png`` and ``metrics.json``
    (``{"without": {...}, "with": {...}}``), plus ``scenario.json`` when the built-in scenario is used."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    builtin = scenario is None
    if scenario is None:
        scenario = demo_scenario()
    say = progress or (lambda _: None)

    def step(mode: str, run: Run | None) -> None:
        if run is None:
            say(f"[{list(LABELS).index(mode) + 1}/2] planning {LABELS[mode]} with {planner} ...")
        else:
            say(f"      {run.result.message} ({run.result.planning_time_s:.2f} s)")

    task = prepare(scenario, cost_weight)
    comparison = compare_with_without(task, planner, time_limit, seed, max_iterations, progress=step)
    if not cv2.imwrite(str(out / "comparison.png"), comparison_picture(comparison)):
        raise OSError(f"could not write {out / 'comparison.png'}")
    (out / "metrics.json").write_text(json.dumps(comparison.metrics, indent=2, allow_nan=False) + "\n")
    if builtin:
        (out / "scenario.json").write_text(json.dumps(DEMO_SCENARIO, indent=2) + "\n")
    return comparison
