"""The with/without comparison harness: plan a scenario's robot task on the costmap without the social layer (the
known map and LiDAR: "without") and on the costmap with it ("with"), measure every path alike, and summarise runs.

One ``Task`` per scenario holds its groups (detected from its people, nobody through a wall of its known map:
``sid.scenario.sight.scenario_groups``), the costmap and planning problem of each mode, and the grid planner's cost
as the reference for cost ratios. Every path is measured against those groups and on the social costmap
(``sid.experiments.path_metrics.result_metrics``), also when the robot planned without the social layer: "the path
went through the conversation" is measured whether or not the robot knew about it, and the two modes' numbers
compare directly. ``sid demo``, ``sid plan``, ``sid
compare``, ``sid reproduce navigation`` and ``sid bench``'s planner stages all plan through here.

World frame (REP-103), metres, seconds. A run's ``cost_ratio`` is its path cost J over the grid planner's J on the
same costmap (``raw_cost_ratio``: the planner's own path before smoothing); ``detour`` is, on a "with" run, its
length over the same planner's "without" length for the same task and seed. Both are None when their yardstick is 0
(a goal at the start).
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any

import numpy as np
from scipy import ndimage
from shapely.geometry import Point

from costmap.grid import GridSpec
from costmap.layered import LayeredCostmap
from costmap.layers.social import group_zone_polygon
from planner.facade import PlanResult, free_regions, plan, resolve_planner
from planner.problem import (
    DEFAULT_COST_WEIGHT,
    CostField,
    EndpointCollisionError,
    PlanningError,
    PlanningProblem,
    WalledOffError,
)
from sid.checks import repeated
from sid.errors import InputError
from sid.experiments.path_metrics import result_metrics
from sid.experiments.progress import Progress
from sid.perception.group import Group
from sid.scenario.build import build_costmap, planning_problem
from sid.scenario.loader import Scenario
from sid.scenario.sight import scenario_groups

__all__ = [
    "Comparison",
    "LABELS",
    "MODES",
    "RunProgress",
    "Run",
    "Task",
    "compare_with_without",
    "people_at_ends",
    "people_in_the_way",
    "people_walling_off",
    "prepare",
    "run_matrix",
    "summarise",
    "zone_warnings",
]

MODES: dict[str, bool] = {"without": False, "with": True}
"""The two costmap modes by name: whether the costmap has the social layer."""
LABELS = {"without": "without recognition (map + LiDAR)", "with": "with recognition (social layer)"}


@dataclass
class Task:
    """A scenario ready to plan in both modes; ``labels`` (free JSON-ready fields) go into every run record."""

    scenario: Scenario
    groups: list[Group]
    costmaps: dict[str, LayeredCostmap]
    problems: dict[str, PlanningProblem]
    labels: dict[str, Any] = field(default_factory=dict)
    _references: dict[str, PlanResult] = field(default_factory=dict, repr=False)

    def reference_cost(self, mode: str) -> float:
        """J of the grid planner's path on the mode's costmap (planned once). Raises ``PlanningError`` naming the
        scenario when its task is impossible."""
        if mode not in self._references:
            try:
                self._references[mode] = self.plan(mode, "grid")
            except PlanningError as exc:
                raise type(exc)(f"{self.scenario.name}: {exc}", *exc.args[1:]) from exc
        return self._references[mode].cost

    def plan(self, mode: str, planner: str, **budget: Any) -> PlanResult:
        """``planner.facade.plan`` on the mode's problem (``budget``: its keyword arguments). A start or goal in
        collision with a person raises the planner's EndpointCollisionError with the person named
        (``people_at_ends``), and a start and goal walled off from each other partly by people its WalledOffError
        with those people named (``people_walling_off``)."""
        try:
            return plan(self.problems[mode], planner, **budget)
        except PlanningError as exc:
            people = people_in_the_way(exc, self.scenario, self.problems[mode])
            if people is None:
                raise
            raise type(exc)(f"{exc}; {people}", *exc.args[1:]) from exc


def prepare(scenario: Scenario, cost_weight: float = DEFAULT_COST_WEIGHT, labels: dict | None = None) -> Task:
    """Detect the scenario's groups (nobody grouped through a wall of its known map) and build the costmap and
    planning problem of each mode."""
    groups = scenario_groups(scenario)
    costmaps = {mode: build_costmap(scenario, social=s, groups=groups if s else []) for mode, s in MODES.items()}
    problems = {mode: planning_problem(scenario, c.master, cost_weight) for mode, c in costmaps.items()}
    return Task(scenario, groups, costmaps, problems, dict(labels or {}))


def zone_warnings(scenario: Scenario, groups: Sequence[Group]) -> list[str]:
    """Messages for the robot's start and goal when they lie inside the interaction zone of one of ``groups`` (of
    ``scenario.people``). The plan is still made: the robot may stand there, or have to go there (to join or serve
    the group), and the metrics report the intrusion."""
    warnings = []
    for end, pose, verb in (("start", scenario.robot.start, "leave"), ("goal", scenario.robot.goal, "enter")):
        point = Point(pose[:2])
        for group in groups:
            if group_zone_polygon(group, scenario.people).covers(point):
                warnings.append(
                    f"the {end} lies inside the interaction zone of group {group.members}: the path has to {verb} it "
                    "(by the shortest way the costs allow); see ospace_intrusion_m"
                )
                break
    return warnings


def _reach(scenario: Scenario) -> float:
    """How far (m) from a person's centre the robot's centre is kept: their body (``lidar.body_radius``, painted
    lethal on the costmap's cells, so within a cell's diagonal of that) and the robot's disc (``robot.radius``)."""
    return scenario.lidar.body_radius + scenario.robot.radius + scenario.grid.resolution * math.sqrt(2.0)


def people_at_ends(scenario: Scenario, ends: Sequence[str] = ("start", "goal")) -> list[str]:
    """A sentence for each of the robot's ``ends`` ("start", "goal") that lies so near a person that the robot's
    disc (``robot.radius``) may touch their body (``lidar.body_radius``, painted lethal on the costmap's cells, so
    within a cell's diagonal of that): the person nearest it, and how far (m, world frame)."""
    robot, body = scenario.robot, scenario.lidar.body_radius
    reach = _reach(scenario)
    sentences = []
    for end in ends:
        pose = robot.start if end == "start" else robot.goal
        near = [(math.hypot(p.x - pose[0], p.y - pose[1]), p) for p in scenario.people]
        near = [(d, p) for d, p in near if d < reach]
        if near:
            distance, person = min(near, key=lambda item: item[0])
            sentences.append(
                f"the {end} is {distance:.2f} m from person {person.id} at ({person.x:.2f}, {person.y:.2f}): a person "
                f"is an obstacle of radius {body:.2f} m (lidar.body_radius) and the robot a disc of radius "
                f"{robot.radius:.2f} m (robot.radius)"
            )
    return sentences


def people_in_the_way(error: PlanningError, scenario: Scenario, problem: PlanningProblem) -> str | None:
    """A sentence naming the people (``scenario.people``) who make ``problem`` fail with ``error``: for a start or
    goal in collision the person at that end (``people_at_ends``), for a start and goal walled off from each other
    those who close the way (``people_walling_off``); None for another failure or when no person is to blame."""
    if isinstance(error, EndpointCollisionError):
        people = people_at_ends(scenario, (error.end,))
        return people[0] if people else None
    if isinstance(error, WalledOffError):
        return people_walling_off(scenario, problem)
    return None


def people_walling_off(scenario: Scenario, problem: PlanningProblem) -> str | None:
    """A sentence naming the people who wall the robot's start off from its goal on ``problem``'s costmap, or None
    when the two are connected or would stay walled off without the people too. The wall is made of the cells the
    robot's centre can reach on the scenario's costmap without people (no social layer) but not on ``problem``'s,
    taken as connected pieces; the people are those who keep the robot off a piece that borders both the start's
    free region and the goal's (``free_regions``), or that lies on a shortest chain of regions and pieces from the
    one to the other (two groups closing a corridor one after the other): a cell of it lies within ``_reach`` of them
    (their centre may lie where the robot cannot stand anyway, against a wall or inside an obstacle)."""
    field = CostField(problem)
    spec = field.spec
    labels = free_regions(field)
    ends = spec.world_to_cell(np.array([problem.start, problem.goal]))
    start, goal = (int(labels[r, c]) for r, c in ends)
    if start == goal or 0 in (start, goal):
        return None
    empty = replace(scenario, people=[], walks={}, conversations=())
    bare = CostField(replace(problem, costmap=build_costmap(empty, social=False, groups=[]).master))
    open_labels = free_regions(bare)
    if int(open_labels[ends[0][0], ends[0][1]]) != int(open_labels[ends[1][0], ends[1][1]]):
        return None
    pieces, count = ndimage.label(bare.plannable & ~field.plannable, structure=np.ones((3, 3), bool))
    boxes, reach = ndimage.find_objects(pieces), _reach(scenario)
    borders = {piece: _bordering(pieces, piece, boxes[piece - 1], labels) - {0} for piece in range(1, count + 1)}
    closing = _on_a_shortest_chain(borders, start, goal)
    wall = [
        person
        for person in scenario.people
        if closing.intersection(_pieces_within(pieces, spec, (person.x, person.y), reach))
    ]
    if not wall:
        return None
    names = ", ".join(f"{p.id} at ({p.x:.2f}, {p.y:.2f})" for p in wall)
    return (
        f"{'people' if len(wall) > 1 else 'person'} {names} {'close' if len(wall) > 1 else 'closes'} the way between "
        f"them (without people it is open): a person is an obstacle of radius {scenario.lidar.body_radius:.2f} m "
        f"(lidar.body_radius) and the robot a disc of radius {scenario.robot.radius:.2f} m (robot.radius)"
    )


def _on_a_shortest_chain(borders: dict[int, set[int]], start: int, goal: int) -> set[int]:
    """The pieces on a shortest chain region - piece - region ... from free region ``start`` to ``goal``, each piece
    joining the regions it borders (``borders``): breadth-first from both ends, a piece lies on one when its two
    distances sum to the chain's length. Empty when no chain joins them."""
    touching: dict[int, set[int]] = {}
    for piece, regions in borders.items():
        for region in regions:
            touching.setdefault(region, set()).add(piece)

    def distances(origin: int) -> dict[tuple[str, int], int]:
        seen, frontier, step = {("region", origin): 0}, [("region", origin)], 0
        while frontier:
            step += 1
            ahead = []
            for kind, node in frontier:
                nexts = (
                    [("piece", p) for p in touching.get(node, ())]
                    if kind == "region"
                    else [("region", r) for r in borders[node]]
                )
                for item in nexts:
                    if item not in seen:
                        seen[item] = step
                        ahead.append(item)
            frontier = ahead
        return seen

    from_start, from_goal = distances(start), distances(goal)
    length = from_start.get(("region", goal))
    if length is None:
        return set()
    return {
        piece
        for piece in borders
        if from_start.get(("piece", piece), length + 1) + from_goal.get(("piece", piece), length + 1) == length
    }


def _bordering(pieces: np.ndarray, piece: int, box: tuple[slice, slice], labels: np.ndarray) -> set[int]:
    """The ``labels`` (free regions) of the cells around piece ``piece`` of ``pieces`` (8-connected), looked at in
    the piece's bounding ``box`` (``ndimage.find_objects``) grown by a cell."""
    grown = tuple(slice(max(part.start - 1, 0), part.stop + 1) for part in box)
    border = ndimage.binary_dilation(pieces[grown] == piece, structure=np.ones((3, 3), bool))
    return set(np.unique(labels[grown][border]).tolist())


def _pieces_within(pieces: np.ndarray, spec: GridSpec, xy: tuple[float, float], reach: float) -> list[int]:
    """The labels (> 0) of ``pieces`` (rows, cols) with a cell centre within ``reach`` (m) of world point ``xy``."""
    (x, y), window = xy, spec.window((xy[0] - reach, xy[1] - reach), (xy[0] + reach, xy[1] + reach))
    if window is None:
        return []
    xs, ys = spec.cell_axes(window)
    near = pieces[window.slices][(xs - x) ** 2 + (ys - y) ** 2 <= reach**2]
    return [int(label) for label in np.unique(near) if label > 0]


@dataclass(frozen=True)
class Run:
    """One plan of a task in one mode: the result, its metrics and its ratios (None where not measured)."""

    scenario: str
    planner: str
    mode: str
    time_limit_s: float
    max_iterations: int | None
    result: PlanResult = field(repr=False)
    metrics: dict
    labels: dict
    cost_ratio: float | None = None
    raw_cost_ratio: float | None = None
    detour: float | None = None

    @property
    def social_layer(self) -> bool:
        return MODES[self.mode]

    def record(self) -> dict[str, Any]:
        """The run as one flat JSON-ready dict: every metric, then the run's fields, then the task's labels (a
        label wins over a metric of the same name, e.g. a task's draw ``seed`` over the planner's seed)."""
        fields = {
            "scenario": self.scenario,
            "planner": self.planner,
            "social_layer": self.social_layer,
            "time_limit_s": self.time_limit_s,
            "max_iterations": self.max_iterations,
            "cost_ratio": self.cost_ratio,
            "raw_cost_ratio": self.raw_cost_ratio,
            "detour": self.detour,
        }
        return self.metrics | fields | self.labels


@dataclass
class Comparison:
    """The runs of one task with one planner and budget, keyed by mode ("without", "with")."""

    task: Task
    runs: dict[str, Run]

    @property
    def metrics(self) -> dict[str, dict]:
        return {mode: run.metrics for mode, run in self.runs.items()}


RunProgress = Callable[[str, Run | None], None]
"""progress(mode, run): called with None before a mode is planned and with its run after."""


def compare_with_without(
    task: Task,
    planner: str,
    time_limit: float,
    seed: int | None = None,
    max_iterations: int | None = None,
    modes: Sequence[str] = tuple(MODES),
    reference: bool = False,
    progress: RunProgress | None = None,
) -> Comparison:
    """Plan the task in each of ``modes`` with the same planner, budget and OMPL seed, and measure each path.

    reference: also compute cost ratios to the grid planner. Raises ``planner.problem.PlanningError`` when the task
    is impossible (naming the scenario when ``reference``) and ValueError for an unknown planner or a bad budget.
    """
    name = resolve_planner(planner)
    measure_on = task.costmaps["with"].master
    runs: dict[str, Run] = {}
    for mode in modes:
        reference_cost = task.reference_cost(mode) if reference else None  # an impossible task fails here, named
        if progress:
            progress(mode, None)
        result = task.plan(mode, name, time_limit=time_limit, seed=seed, max_iterations=max_iterations)
        metrics = result_metrics(result, task.scenario.people, task.groups, measure_on)
        ratio = raw_ratio = detour = None  # also where the yardstick is 0 m long: a goal at the start
        if reference_cost is not None and reference_cost > 0 and result.success:
            ratio, raw_ratio = result.cost / reference_cost, result.raw_cost / reference_cost
        without = runs.get("without")
        if mode == "with" and result.success and without is not None and without.result.success:
            without_length = without.metrics["path_length_m"]
            detour = metrics["path_length_m"] / without_length if without_length > 0 else None
        runs[mode] = Run(
            task.scenario.name, name, mode, time_limit, max_iterations, result, metrics, task.labels,
            ratio, raw_ratio, detour,
        )  # fmt: skip
        if progress:
            progress(mode, runs[mode])
    return Comparison(task, runs)


def run_matrix(
    tasks: Sequence[Task],
    planners: Sequence[str],
    runs: int = 3,
    time_limits: Sequence[float] = (0.5,),
    modes: Sequence[str] = tuple(MODES),
    max_iterations: int | None = None,
    progress: Progress | None = None,
) -> list[Run]:
    """Every planner (grid: once, it is deterministic; the others with OMPL seeds 1..``runs``) for every time limit
    and task, in each mode, with cost ratios to the grid reference. The runs are told apart by scenario name and
    planner: a planner given twice, or two tasks whose scenarios share a name, are refused (ValueError), since their
    runs would be pooled into one row. Every task's grid references are planned first, so an impossible task raises
    ``planner.problem.PlanningError`` naming its scenario before any run. ``progress`` is called before each plan and
    once at the end."""
    names = [resolve_planner(p) for p in planners]
    if runs < 1:
        raise InputError(f"runs must be at least 1, got {runs}")
    twice = repeated(names)
    if twice is not None:
        raise InputError(f"planner {twice} is given twice: its runs would be counted twice")
    twice = repeated([task.scenario.name for task in tasks])
    if twice is not None:
        raise InputError(
            f"two scenarios are named {twice!r}: their runs would be pooled into one row; give each its own 'name'"
        )
    for task in tasks:  # an impossible task stops the matrix here, named, before any run is spent
        for mode in modes:
            task.reference_cost(mode)
    jobs = [
        (task, limit, name, seed)
        for task in tasks
        for limit in time_limits
        for name in names
        for seed in ([None] if name == "grid" else range(1, runs + 1))
    ]
    total = len(jobs) * len(modes)
    out: list[Run] = []

    def step(what: str, mode: str, run: Run | None) -> None:
        if run is None and progress:
            progress(len(out) + list(modes).index(mode), total, f"{what}, {mode} the social layer")

    for task, limit, name, seed in jobs:
        what = f"{task.scenario.name}: {name}" + ("" if seed is None else f" seed {seed}")
        comparison = compare_with_without(task, name, limit, seed, max_iterations, modes, True, partial(step, what))
        out.extend(comparison.runs.values())
    if progress:
        progress(total, total, "done")
    return out


def _stat(fn: Callable[[list], float], values: Iterable[float | None]) -> float | None:
    """``fn`` (median, mean, min, max) of the values that are not None; None when there are none."""
    present = [v for v in values if v is not None]
    return float(fn(present)) if present else None


def summarise(records: Sequence[dict], by: Sequence[str] = ("planner",)) -> list[dict]:
    """One row per value of the ``by`` fields and costmap mode, in order of first appearance, "without" first.

    ``records``: ``Run.record()`` dicts (``cost_ratio``, ``raw_cost_ratio`` and ``detour`` may be left out). Rates
    and path statistics are over successful runs, planning time over all runs. Row fields: the ``by`` fields,
    social_layer, runs, success_rate, median_planning_time_s, median_cost_ratio, worst_cost_ratio,
    median_raw_cost_ratio, intrusion_rate (share of paths entering a group zone), mean_intrusion_m,
    median_intrusion_m, median_intrusion_when_intruding_m, crossing_rate, median_min_person_distance_m,
    worst_min_person_distance_m, median_length_ratio, median_detour (None where not measured).
    """
    buckets: dict[tuple, dict[bool, list[dict]]] = {}
    for record in records:
        buckets.setdefault(tuple(record[k] for k in by), {}).setdefault(record["social_layer"], []).append(record)
    rows = []
    for values, modes in buckets.items():
        for social in sorted(modes):
            members = modes[social]
            ok = [r for r in members if r["success"]]
            intrusion = [r["ospace_intrusion_m"] for r in ok]
            intruding = [v for v in intrusion if v > 0]
            distances = [r["min_person_distance_m"] for r in ok]
            rows.append(
                dict(zip(by, values, strict=True))
                | {
                    "social_layer": social,
                    "runs": len(members),
                    "success_rate": len(ok) / len(members),
                    "median_planning_time_s": _stat(statistics.median, (r["planning_time_s"] for r in members)),
                    "median_cost_ratio": _stat(statistics.median, (r.get("cost_ratio") for r in ok)),
                    "worst_cost_ratio": _stat(max, (r.get("cost_ratio") for r in ok)),
                    "median_raw_cost_ratio": _stat(statistics.median, (r.get("raw_cost_ratio") for r in ok)),
                    "intrusion_rate": len(intruding) / len(ok) if ok else None,
                    "mean_intrusion_m": _stat(statistics.fmean, intrusion),
                    "median_intrusion_m": _stat(statistics.median, intrusion),
                    "median_intrusion_when_intruding_m": _stat(statistics.median, intruding),
                    "crossing_rate": sum(bool(r["crosses_group"]) for r in ok) / len(ok) if ok else None,
                    "median_min_person_distance_m": _stat(statistics.median, distances),
                    "worst_min_person_distance_m": _stat(min, distances),
                    "median_length_ratio": _stat(statistics.median, (r["length_ratio"] for r in ok)),
                    "median_detour": _stat(statistics.median, (r.get("detour") for r in ok)) if social else None,
                }
            )
    return rows
