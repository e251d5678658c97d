"""Plan a scenario's robot task on its costmap, measure it and write ``path.json`` and ``plan.png``.

The groups used to measure a path are always detected from the scenario's people
(``sid.perception.groups.detect_groups``),
also when the robot planned without the social layer, so "the path went through the conversation" is measured
whether or not the robot knew about it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from costmap.grid import Costmap2D
from costmap.layered import LayeredCostmap
from planner.facade import DEFAULT_PLANNER, PlanResult, plan
from planner.metrics import result_metrics
from planner.problem import DEFAULT_COST_WEIGHT
from planner.render import WITH_COLOUR, WITHOUT_COLOUR, PathStyle, add_header, add_table, render_paths
from sid.perception.groups import Group, detect_groups
from sid.scenario.build import build_costmap, planning_problem
from sid.scenario.loader import Scenario


@dataclass
class ScenarioPlan:
    """One plan of a scenario: the costmap it used (social layer or not), the result and its metrics."""

    scenario: Scenario
    social: bool
    groups: list[Group]
    costmap: LayeredCostmap
    result: PlanResult
    metrics: dict


def plan_scenario(
    scenario: Scenario,
    social: bool = True,
    planner: str = DEFAULT_PLANNER,
    time_limit: float = 0.5,
    seed: int | None = None,
    max_iterations: int | None = None,
    cost_weight: float = DEFAULT_COST_WEIGHT,
    groups: list[Group] | None = None,
    metrics_costmap: Costmap2D | None = None,
) -> ScenarioPlan:
    """Build the scenario's costmap (with or without the social layer) and plan its robot task on it.

    groups: the scenario's groups (None: detected from its people). metrics_costmap: where the path's cost
    integral is measured (None: the costmap planned on). Raises ``planner.problem.PlanningError`` for an
    impossible task and ValueError for an unknown planner or bad budget.
    """
    groups = detect_groups(scenario.people, scenario.group_params) if groups is None else groups
    layered = build_costmap(scenario, social=social, groups=groups if social else [])
    problem = planning_problem(scenario, layered.master, cost_weight)
    result = plan(problem, planner, time_limit=time_limit, seed=seed, max_iterations=max_iterations)
    metrics = result_metrics(result, scenario.people, groups, metrics_costmap or layered.master)
    return ScenarioPlan(scenario, social, groups, layered, result, metrics)


def path_record(sp: ScenarioPlan) -> dict:
    """The JSON record of a plan: every metric at the top level, plus the waypoints in the world frame."""
    return sp.metrics | {
        "scenario": sp.scenario.name,
        "social_layer": sp.social,
        "frame": "world (REP-103: x forward, y left), metres",
        "start": list(sp.scenario.robot.start[:2]),
        "goal": list(sp.scenario.robot.goal[:2]),
        "waypoints": np.round(sp.result.path, 4).tolist(),
    }


def plan_picture(sp: ScenarioPlan) -> np.ndarray:
    """BGR image: the costmap planned on, the detected group zones, the robot task, the path and its metrics."""
    style = PathStyle("with the social layer" if sp.social else "without the social layer", WITH_COLOUR)
    if not sp.social:
        style = PathStyle(style.label, WITHOUT_COLOUR)
    r, m = sp.result, sp.metrics
    paths = [(r.path, style)] if r.success else []
    img, _ = render_paths(sp.costmap, paths, robot=sp.scenario.robot, groups=sp.groups)
    seed = f", seed {r.seed}" if r.seed is not None else ""
    title = f"{sp.scenario.name}: {r.planner} {style.label}"
    subtitle = r.message + seed
    img = add_header(img, title, subtitle)
    if not r.success:
        return img
    cells = [
        f"{m['path_length_m']:.2f} m",
        f"{m['ospace_intrusion_m']:.2f} m",
        "yes" if m["crosses_group"] else "no",
        "-" if m["min_person_distance_m"] is None else f"{m['min_person_distance_m']:.2f} m",
        f"{100 * m['personal_space_fraction']:.0f} %",
        f"{m['planning_time_s']:.2f} s",
    ]
    header = ["path", "length", "in group zone", "crosses group", "closest person", "within 1.2 m", "planning"]
    return add_table(img, header, [(style, [style.label, *cells])])


def write_plan(sp: ScenarioPlan, out_dir: str | Path) -> dict[str, Path]:
    """Write ``path.json`` and ``plan.png`` into ``out_dir`` (created if missing); returns their paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {"path": out / "path.json", "picture": out / "plan.png"}
    paths["path"].write_text(json.dumps(path_record(sp), indent=2, allow_nan=False) + "\n")
    if not cv2.imwrite(str(paths["picture"]), plan_picture(sp)):
        raise OSError(f"could not write {paths['picture']}")
    return paths
