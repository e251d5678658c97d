"""The navigation study: the with/without comparison (``sid.experiments.harness``) over a family of tasks.

Every task is the demo's corridor (11 x 7 m, walls at y = +-3 m, two boxes; ``sid.experiments.demo.DEMO_SCENARIO``) with
one conversation in its middle and the robot crossing the corridor lengthwise past it. World frame (REP-103),
metres, radians. A task is drawn from ``numpy.random.default_rng([base_seed, layout index, seed])``:

- the conversation: a layout of ``NAV_LAYOUTS`` (group sizes 2-5: the paper's S1-S5 and wider pairs and
  semicircles), its centre at (4.5, U(-0.3, 0.3)), turned by U(0, 360) deg, every member facing the centre, then
  Gaussian jitter of 5 cm on positions and 5 deg on facing directions (people never stand on an exact circle);
- the robot: start (0, U(-0.6, 0.6)), goal (9, U(-0.6, 0.6)), so the straight route passes within 0.6 m of the
  group's centre: the group stands in the way, the case where recognising it matters (a route that misses the
  group measures nothing). Each draw is planned in both directions ("forward": start on the left, "reverse":
  start and goal swapped), so the robot meets every layout from both sides.

For each task and planner, ``sid.experiments.harness.compare_with_without`` plans on the costmap without the social
layer ("without") and on the costmap with it ("with"), with the same budget and OMPL seed, and measures both
paths against the same groups, detected from the task's people (``sid.perception.groups.detect_groups`` on exact
positions: this study is about navigation, not perception). ``sid.experiments.harness.summarise`` gives, per planner
(or layout) and costmap: success rate, o-space intrusion rate (share of successful paths entering a group zone) and
length, group-crossing rate, minimum distance to people, path-length ratio (length / straight line), detour (length
with / length without, per task) and planning time; docs/reproduction.md says where these metrics come from.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from planner.facade import DEFAULT_PLANNER, resolve_planner
from planner.problem import DEFAULT_COST_WEIGHT, PlanningError
from sid.checks import check_number, check_whole, repeated
from sid.errors import InputError
from sid.experiments.demo import DEMO_SCENARIO
from sid.experiments.harness import Comparison, compare_with_without, prepare
from sid.experiments.progress import Progress
from sid.scenario.loader import Scenario, scenario_from_dict
from sid.synthetic.layouts import LAYOUTS

__all__ = [
    "CENTRE_LATERAL_M",
    "DIRECTIONS",
    "ENDPOINT_LATERAL_M",
    "GROUP_CENTRE_X",
    "GroupLayout",
    "JITTER_THETA_RAD",
    "JITTER_XY_M",
    "NAV_LAYOUTS",
    "NavSettings",
    "NavTask",
    "NavigationResult",
    "RUN_KEYS",
    "navigation_tasks",
    "run_navigation",
    "task_scenario",
]


@dataclass(frozen=True)
class GroupLayout:
    """People on a circle of ``radius`` (m) around the group's centre at polar angles ``angles_deg``, facing it."""

    description: str
    angles_deg: tuple[float, ...]
    radius: float

    @property
    def size(self) -> int:
        return len(self.angles_deg)


NAV_LAYOUTS: dict[str, GroupLayout] = {
    **{name: GroupLayout(spec.description, spec.angles_deg, spec.radius) for name, spec in LAYOUTS.items()},
    "P2": GroupLayout("two people 1.4 m apart facing each other", (90.0, -90.0), 0.70),
    "T3": GroupLayout("three on a triangle of 1.56 m sides (the demo's)", (90.0, 210.0, 330.0), 0.90),
    "C5": GroupLayout("five in a circle of radius 0.9 m", (0.0, 72.0, 144.0, 216.0, 288.0), 0.90),
    "H5": GroupLayout("five in a semicircle of radius 0.85 m", (-72.0, -36.0, 0.0, 36.0, 72.0), 0.85),
}
"""The family's conversations: S1-S5 as ``sid.synthetic.layouts`` defines them, plus a wider pair, the demo's
triangle, a circle and a semicircle of five; every o-space radius stays within the group detector's default
``spread_threshold`` (1.0 m), so detection on exact positions finds each conversation."""

GROUP_CENTRE_X = 4.5
CENTRE_LATERAL_M = 0.3
ENDPOINT_LATERAL_M = 0.6
JITTER_XY_M = 0.05
JITTER_THETA_RAD = math.radians(5.0)
DIRECTIONS = ("forward", "reverse")


@dataclass(frozen=True)
class NavTask:
    """One robot task of the family: its name, layout, draw seed, direction and scenario."""

    name: str
    layout: str
    seed: int
    direction: str
    scenario: Scenario = field(repr=False)

    @property
    def group_size(self) -> int:
        return NAV_LAYOUTS[self.layout].size


def task_scenario(layout_name: str, seed: int, direction: str = "forward", base_seed: int = 0) -> Scenario:
    """The scenario of one task (see the module docstring for how it is drawn)."""
    if layout_name not in NAV_LAYOUTS:
        raise InputError(f"unknown navigation layout {layout_name!r}; known: {', '.join(NAV_LAYOUTS)}")
    if direction not in DIRECTIONS:
        raise InputError(f"direction must be one of {DIRECTIONS}, got {direction!r}")
    spec = NAV_LAYOUTS[layout_name]
    rng = np.random.default_rng([base_seed, list(NAV_LAYOUTS).index(layout_name), seed])
    centre = np.array([GROUP_CENTRE_X, rng.uniform(-CENTRE_LATERAL_M, CENTRE_LATERAL_M)])
    phi = np.radians(np.asarray(spec.angles_deg)) + rng.uniform(0.0, 2 * math.pi)
    xy = centre + spec.radius * np.stack([np.cos(phi), np.sin(phi)], axis=1)
    xy += rng.normal(0.0, JITTER_XY_M, xy.shape)
    theta = phi + math.pi + rng.normal(0.0, JITTER_THETA_RAD, len(phi))
    theta = np.angle(np.exp(1j * theta))
    start_y, goal_y = rng.uniform(-ENDPOINT_LATERAL_M, ENDPOINT_LATERAL_M, 2)
    start, goal = [0.0, float(start_y), 0.0], [9.0, float(goal_y), 0.0]
    if direction == "reverse":
        start, goal = [goal[0], goal[1], math.pi], [start[0], start[1], math.pi]
    data = copy.deepcopy(DEMO_SCENARIO)
    data["name"] = f"{layout_name} seed {seed} {direction}"
    data["people"] = [
        {"id": i + 1, "x": round(float(x), 4), "y": round(float(y), 4), "theta": round(float(t), 4)}
        for i, ((x, y), t) in enumerate(zip(xy, theta, strict=True))
    ]
    data["robot"] = {"start": start, "goal": goal, "radius": DEMO_SCENARIO["robot"]["radius"]}
    return scenario_from_dict(data)


def navigation_tasks(
    seeds: int, layouts: Sequence[str] | None = None, directions: Sequence[str] = DIRECTIONS, base_seed: int = 0
) -> list[NavTask]:
    """Tasks for every layout x draw seed 1..``seeds`` x direction."""
    check_whole("navigation", "seeds", seeds, low=1)
    names = list(NAV_LAYOUTS) if layouts is None else list(layouts)
    return [
        NavTask(
            f"{name} seed {seed} {direction}", name, seed, direction, task_scenario(name, seed, direction, base_seed)
        )
        for name in names
        for seed in range(1, int(seeds) + 1)
        for direction in directions
    ]


@dataclass(frozen=True)
class NavSettings:
    """Planner budget of the study: planners, time limit per plan (s), iteration cap (None: the time decides),
    cost weight; OMPL is seeded with 1 + the task's index, so capped runs repeat exactly."""

    planners: tuple[str, ...] = ("bitstar", "informed_rrtstar", "rrtstar", "fmtstar", "rrtconnect", "grid")
    time_limit: float = 0.5
    max_iterations: int | None = None
    cost_weight: float = DEFAULT_COST_WEIGHT

    def __post_init__(self) -> None:
        if not self.planners:
            raise InputError("navigation: give at least one planner")
        # resolve_planner raises ValueError naming an unknown planner
        twice = repeated([resolve_planner(name) for name in self.planners])
        if twice is not None:  # as run_matrix: its plans would be counted twice in the report
            raise InputError(f"navigation: planner {twice} is given twice: its runs would be counted twice")
        check_number("navigation", "time limit", self.time_limit, low=0, low_open=True, unit="seconds")
        if self.max_iterations is not None and self.max_iterations < 1:
            raise InputError(f"navigation: iteration cap must be >= 1, got {self.max_iterations}")


# The fields of a run kept in the report: the task's labels, then ``Run.record`` keys.
RUN_KEYS = (
    "task",
    "layout",
    "group_size",
    "seed",
    "direction",
    "planner",
    "social_layer",
    "groups_detected",
    "group_detected_whole",
    "success",
    "path_length_m",
    "length_ratio",
    "ospace_intrusion_m",
    "crosses_group",
    "min_person_distance_m",
    "personal_space_fraction",
    "planning_time_s",
    "message",
    "detour",
)


@dataclass
class NavigationResult:
    """Runs (one record per task x planner x costmap, ``RUN_KEYS``), tasks that could not be planned at all
    (name -> reason), and, for the example picture, the comparison where the social layer avoided the most o-space
    intrusion with the default planner (or the first one given; None when it avoided none)."""

    settings: NavSettings
    tasks: int
    runs: list[dict] = field(default_factory=list)
    impossible: dict[str, str] = field(default_factory=dict)
    example: Comparison | None = None


def run_navigation(
    tasks: Sequence[NavTask], settings: NavSettings = NavSettings(), progress: Progress | None = None
) -> NavigationResult:
    """Plan every task with every planner, without and with the social layer; see the module docstring."""
    result = NavigationResult(settings, len(tasks))
    names = [resolve_planner(p) for p in settings.planners]
    example_planner = DEFAULT_PLANNER if DEFAULT_PLANNER in names else names[0]
    best_gain = 0.0  # the example must show an intrusion the social layer avoided
    total = len(tasks) * len(names)
    for index, nav in enumerate(tasks):
        task = prepare(nav.scenario, settings.cost_weight)
        members = sorted(len(g.members) for g in task.groups)
        task.labels |= {
            "task": nav.name,
            "layout": nav.layout,
            "group_size": nav.group_size,
            "seed": nav.seed,
            "direction": nav.direction,
            "groups_detected": members,
            "group_detected_whole": members == [nav.group_size],
        }
        for j, planner in enumerate(names):
            if progress:
                progress(index * len(names) + j, total, f"{nav.name}: {planner}")
            try:
                comparison = compare_with_without(
                    task, planner, settings.time_limit, 1 + index, settings.max_iterations
                )
            except PlanningError as exc:
                result.impossible[nav.name] = str(exc)
                break
            # A failed run has no path metrics (length_ratio, ...): they are recorded as None.
            result.runs += [{key: run.record().get(key) for key in RUN_KEYS} for run in comparison.runs.values()]
            without, with_ = comparison.metrics["without"], comparison.metrics["with"]
            if planner == example_planner and without["success"] and with_["success"]:
                gain = without["ospace_intrusion_m"] - with_["ospace_intrusion_m"]
                if gain > best_gain:
                    best_gain, result.example = gain, comparison
    if progress:
        progress(total, total, "done")
    return result
