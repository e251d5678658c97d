"""The project's main result: plan the same task without and with group recognition, and show the difference.

``compare_with_without`` works on any scenario: groups are detected from the scenario's people
(``sid.perception.groups.detect_groups``); the robot *without* recognition plans on the LiDAR costmap, where people are
only obstacles; the robot *with* recognition plans on the costmap with the social layer (personal spaces and group
zones). Both paths are measured against the same detected groups and on the social costmap, so their numbers compare
directly. ``DEMO_SCENARIO`` is the built-in task ``sid demo`` runs: a corridor, a robot, and its goal behind three
people in conversation, with a fourth person standing alone.

Goal inside a group zone: the plan is made and returned, not refused. The robot may have to go there (to join or
serve the group); the zone's cost makes the path enter it by the shortest way, the metrics report the intrusion
and set ``goal_in_group_zone``, and ``goal_zone_warning`` gives the message commands print.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import cv2
from shapely.geometry import Point

from costmap.layered import LayeredCostmap
from costmap.layers.social import group_zone_polygon
from planner.facade import DEFAULT_PLANNER, PlanResult
from planner.problem import DEFAULT_COST_WEIGHT
from planner.render import WITH_COLOUR, WITHOUT_COLOUR, PathStyle, add_header, add_table, render_paths
from sid.experiments.scenario_plan import plan_scenario
from sid.perception.groups import Group, detect_groups
from sid.scenario.build import build_costmap
from sid.scenario.loader import Scenario, scenario_from_dict


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
only guards against a machine far slower than the one this was measured on."""


def demo_scenario() -> Scenario:
    return scenario_from_dict(DEMO_SCENARIO, default_name="demo")


@dataclass
class Comparison:
    """Plans of one scenario without ("without") and with ("with") group recognition, keyed alike."""

    scenario: Scenario
    groups: list[Group]
    costmaps: dict[str, LayeredCostmap] = field(default_factory=dict)
    results: dict[str, PlanResult] = field(default_factory=dict)
    metrics: dict[str, dict] = field(default_factory=dict)


LABELS = {"without": "without recognition (LiDAR only)", "with": "with recognition (social layer)"}
STYLES = {
    "without": PathStyle(LABELS["without"], WITHOUT_COLOUR, dashed=True),
    "with": PathStyle(LABELS["with"], WITH_COLOUR),
}


def goal_zone_warning(scenario: Scenario, groups: list[Group]) -> str | None:
    """A message when the robot's goal lies inside a group's interaction zone, else None."""
    goal = Point(scenario.robot.goal[:2])
    for group in groups:
        if group_zone_polygon(group, scenario.people).covers(goal):
            return (
                f"the goal lies inside the interaction zone of group {group.members}: the path has to enter it "
                "(by the shortest way the costs allow); see ospace_intrusion_m"
            )
    return None


def compare_with_without(
    scenario: Scenario,
    planner: str = DEFAULT_PLANNER,
    time_limit: float = 5.0,
    seed: int | None = DEMO_SEED,
    max_iterations: int | None = DEMO_ITERATIONS,
    cost_weight: float = DEFAULT_COST_WEIGHT,
    progress: Callable[[str], None] | None = None,
) -> Comparison:
    """Detect the groups, build both costmaps, plan on each with the same planner and budget, and measure.

    Raises ``planner.problem.PlanningError`` when the task is impossible on either costmap (the message names it).
    """
    say = progress or (lambda _: None)
    groups = detect_groups(scenario.people, scenario.group_params)
    social_costs = build_costmap(scenario, social=True, groups=groups).master  # both paths are measured on it
    comparison = Comparison(scenario, groups)
    for step, (key, social) in enumerate((("without", False), ("with", True)), start=1):
        say(f"[{step}/2] planning {LABELS[key]} with {planner} ...")
        sp = plan_scenario(
            scenario, social, planner, time_limit, seed, max_iterations, cost_weight, groups, social_costs
        )
        say(f"      {sp.result.message} ({sp.result.planning_time_s:.2f} s)")
        comparison.costmaps[key], comparison.results[key], comparison.metrics[key] = sp.costmap, sp.result, sp.metrics
    return comparison


def _cells(m: dict, everything: dict[str, dict]) -> list[str]:
    if not m["success"]:
        return ["no path", "-", "-", "-", "-", f"{m['planning_time_s']:.2f} s"]
    base = everything.get("without", {})
    longer = ""
    if m is not base and base.get("success"):
        longer = f" ({100 * (m['path_length_m'] / base['path_length_m'] - 1):+.0f} %)"
    return [
        f"{m['path_length_m']:.2f} m{longer}",
        f"{m['ospace_intrusion_m']:.2f} m",
        "yes" if m["crosses_group"] else "no",
        f"{m['min_person_distance_m']:.2f} m" if m["min_person_distance_m"] is not None else "-",
        f"{100 * m['personal_space_fraction']:.0f} %",
        f"{m['planning_time_s']:.2f} s",
    ]


HEADER = ["path", "length", "in group zone", "crosses group", "closest person", "within 1.2 m", "planning"]


def format_table(comparison: Comparison) -> str:
    """The comparison as a plain-text table (one row per robot)."""
    rows = [HEADER] + [[LABELS[k], *_cells(m, comparison.metrics)] for k, m in comparison.metrics.items()]
    widths = [max(len(r[i]) for r in rows) for i in range(len(HEADER))]
    lines = ["  ".join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)) for row in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def comparison_picture(comparison: Comparison):
    """BGR image: the social costmap with both paths, people, group zones, robot and goal, and the metrics table."""
    result = comparison.results["with"]
    title = "Without group recognition the robot cuts through the conversation; with it, it goes around"
    subtitle = (
        f"{comparison.scenario.name}. Colours: the costmap with the social layer. Planner {result.planner}, "
        f"seed {result.seed}. The dashed path was planned on the LiDAR-only costmap."
    )
    paths = [(r.path, STYLES[k]) for k, r in comparison.results.items() if r.success]
    img, _ = render_paths(comparison.costmaps["with"], paths, robot=comparison.scenario.robot, groups=comparison.groups)
    rows = [(STYLES[k], [LABELS[k], *_cells(m, comparison.metrics)]) for k, m in comparison.metrics.items()]
    return add_table(add_header(img, title, subtitle), HEADER, rows)


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
    scenario = demo_scenario() if builtin else scenario
    comparison = compare_with_without(scenario, planner, time_limit, seed, max_iterations, cost_weight, progress)
    if not cv2.imwrite(str(out / "comparison.png"), comparison_picture(comparison)):
        raise OSError(f"could not write {out / 'comparison.png'}")
    (out / "metrics.json").write_text(json.dumps(comparison.metrics, indent=2, allow_nan=False) + "\n")
    if builtin:
        (out / "scenario.json").write_text(json.dumps(DEMO_SCENARIO, indent=2) + "\n")
    return comparison
