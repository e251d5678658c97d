"""The closed loop: sense, perceive, update the costmap, replan when needed, follow the path, move; until the goal, a
collision or the time limit.

Per step of ``1 / rate_hz`` seconds, at time t (map frame, metres, radians, seconds):

1. the people move to their scripted poses at t (``SimWorld.people_at``); a robot disc overlapping an obstacle or a
   person's body (``lidar.body_radius``) at any moment of the step that ends at t (robot and people moving straight
   over it) is a collision and ends the run (also when a walker, who never avoids the robot, walks into it while it
   stands still; the reason says so); the robot within ``goal_tolerance_m`` of the goal
   ends it with success; t past ``time_limit_s`` ends it without;
2. the 2D LiDAR scans from the robot's pose (``sid.scenario.lidar.simulate_scan``: obstacles and people); with the
   social layer the camera sees the people (``sid.experiments.simulate.perception``) and the group detector groups
   them (``sid.perception.groups.detect_groups``);
3. the layered costmap updates in the map frame: the scenario's obstacles as the known map (static layer; none with
   ``unknown_map``), the scan (LiDAR layer), people and groups (social layer, left out with ``social=False``),
   inflation;
4. the planner (``planner.facade.plan``) replans from the robot's position when the rest of the path is blocked on
   the new costmap and every ``replan_period_s`` (also while it has no path); a periodic plan replaces the current
   path only when it costs at least ``replan_gain`` less than the rest of the current one on the same costmap;
5. the path follower (``sid.experiments.simulate.follower``, regulated pure pursuit) gives a velocity command (zero
   without a path: the robot waits) and the differential-drive model moves the robot
   (``sid.experiments.simulate.robot``).

Seed 0 runs the world as written, seed k >= 1 its jittered people (``sid.experiments.simulate.world.jittered``);
the seed also draws the camera's noise. A task that the known map makes impossible (start or goal in an obstacle,
walled off) ends at t = 0 with the planner's reason. Runs are deterministic for the same world and options: noise
is drawn from ``[seed, step]``, the grid planner is deterministic and OMPL's planners are seeded per plan (with a
time budget, OMPL's own results may still vary with the machine's load; use ``--planner grid``, the default, for
exact repeats).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from costmap.grid import INSCRIBED, Costmap2D
from costmap.scan import LaserScan
from planner.facade import PlanResult, check_endpoints, plan, resolve_planner
from planner.problem import (
    DEFAULT_COST_WEIGHT,
    CostField,
    EndpointCollisionError,
    PlanningError,
    PlanningProblem,
)
from planner.validity import interpolate
from sid.errors import InputError
from sid.experiments.harness import people_in_the_way
from sid.experiments.simulate.follower import FollowerParams, follow, remaining
from sid.experiments.simulate.perception import (
    SIM_CALIBRATION,
    CameraSensing,
    ExactSensing,
    LidarSensing,
    Sensing,
)
from sid.experiments.simulate.robot import RobotState, step
from sid.experiments.simulate.world import SimWorld, collision, jittered, obstacle_geometry
from sid.perception.group import Group
from sid.perception.people import Person
from sid.perception.pipeline import Pipeline, PoseFn, image_pose
from sid.perception.robot_pose import RobotPose
from sid.scenario.build import build_costmap, map_walls
from sid.scenario.lidar import simulate_scan
from sid.scenario.sight import scenario_groups, scenario_walls
from sid.stream import SocialStream
from sid.synthetic.pose import TruthPose
from sid.synthetic.sensor import SyntheticCamera

__all__ = [
    "MAX_CONTROL_PERIOD_S",
    "Observer",
    "PERCEPTIONS",
    "RunOptions",
    "RunTrace",
    "StepView",
    "make_sensing",
    "simulate",
]

PERCEPTIONS = ("camera", "exact")
MAX_CONTROL_PERIOD_S = 0.25
"""The longest the path follower's command is held (s): a world stepped more slowly (rate_hz below 4) runs the
follower several times per step, as a robot's controller runs at its own rate whatever its camera's (held for a whole
slow step, a turn in place passes the bend's bearing and turns back, step after step)."""


@dataclass(frozen=True)
class RunOptions:
    """How one run is made: social layer or not, planner and its budget (s), seed, pose model (None: TruthPose),
    perception (``camera`` or ``exact``), whether the map is unknown, the replanning policy (period s, gain)."""

    social: bool = True
    planner: str = "grid"
    seed: int = 0
    model: Path | None = None
    perception: str = "camera"
    unknown_map: bool = False
    plan_time_s: float = 0.25
    replan_period_s: float = 1.0
    replan_gain: float = 0.1
    cost_weight: float = DEFAULT_COST_WEIGHT

    def __post_init__(self) -> None:
        resolve_planner(self.planner)
        if self.perception not in PERCEPTIONS:
            raise InputError(f"perception must be one of {', '.join(PERCEPTIONS)}, got {self.perception!r}")
        if not (isinstance(self.seed, int) and 0 <= self.seed < 2**31):
            raise InputError(f"seed must be a whole number from 0 to {2**31 - 1}, got {self.seed!r}")


@dataclass
class StepView:
    """What one step showed (for pictures): time (s), robot state, true and seen people, groups, scan, costmap,
    the current path (N, 2) and the camera image (RGB) when there is one."""

    t: float
    robot: RobotState
    people: list[Person]
    seen: list[Person]
    groups: list[Group]
    scan: LaserScan
    costmap: Costmap2D
    path: np.ndarray | None
    image: np.ndarray | None


@dataclass
class RunTrace:
    """A finished run: how it ended, the trajectory ([t, x, y, yaw] rows) and the true people and groups at every
    step (for the metrics), the planner's calls and adopted replans, and the planning time (s: the wall time of
    every planner call, failed ones included)."""

    success: bool
    reason: str
    collisions: int
    time_s: float
    trajectory: list[tuple[float, float, float, float]] = field(default_factory=list)
    truth: list[tuple[list[Person], list[Group]]] = field(default_factory=list, repr=False)
    plans: int = 0
    replans: int = 0
    planning_time_s: float = 0.0


Observer = Callable[[StepView], None]


def _collision_reason(hit: str, t: float, k: int, state: RobotState, walkers: Iterable[int]) -> str:
    """The run's reason for a collision with ``hit`` ("obstacle", "person N") at step ``k`` (time ``t``, s): at the
    first step the robot starts overlapping it; scripted walkers do not avoid the robot, so one may walk into it
    while it stands still (waiting for a path)."""
    if k == 0:
        note = " (where the robot starts: its disc overlaps it)"
    elif state.v == 0.0 and hit in {f"person {pid}" for pid in walkers}:
        note = " (the robot was standing still: the person walked into it)"
    else:
        note = ""
    return f"collision with {hit} at t = {t:.1f} s{note}"


def make_sensing(world: SimWorld, options: RunOptions, color: bool = False, walls: Costmap2D | None = None) -> Sensing:
    """The costmap and the sensing the options ask for (``sid.experiments.simulate.perception``). The costmap's
    static layer holds the scenario's obstacles (none with ``unknown_map``); ``color``: render the camera's colour
    image (for pictures; a pose model always gets one), which changes no result of ``TruthPose``; ``walls``: the
    scenario's map file's walls (``map_walls``), which hide people from exact perception."""
    scenario = world.scenario
    known = replace(scenario, people=[])
    if options.unknown_map:
        known = replace(known, obstacles=[], static_map=None)
    if not options.social:
        return LidarSensing(build_costmap(known, social=False, groups=[]))
    # people come as tracks (the camera's, or exact perception's perfect ones): the social layer draws tracks instead
    plugins = tuple("tracked_people" if name == "social" else name for name in scenario.layers.plugins)
    costmap = build_costmap(known, social=True, groups=[], params=replace(scenario.layers, plugins=plugins))
    if options.perception == "exact":
        return ExactSensing(costmap, scenario.obstacles, scenario.group_params, scenario.walks,
                            world.settings.rate_hz, scenario.lidar.body_radius, walls=walls)  # fmt: skip
    if options.model is None:
        pose: PoseFn = TruthPose()
    else:
        from sid.perception.pose import load_pose_estimator

        pose = image_pose(load_pose_estimator(options.model))
    camera = SyntheticCamera(calibration=SIM_CALIBRATION, shaded_color=color or options.model is not None,
                             fps=world.settings.rate_hz)  # fmt: skip
    stream = SocialStream(Pipeline(pose, group_params=scenario.group_params, group=False), costmap)
    return CameraSensing(stream, camera, scenario, options.seed)


def _ompl_seed(seed: int, plans: int) -> int:
    return 1 + (seed * 100_003 + plans) % (2**31 - 2)


def _free_start(field_: CostField, xy: tuple[float, float], reach: float = 0.5) -> tuple[float, float] | None:
    """The centre of the free cell nearest ``xy`` within ``reach`` m (the robot has grazed an inscribed cell)."""
    spec = field_.spec
    window = spec.window((xy[0] - reach, xy[1] - reach), (xy[0] + reach, xy[1] + reach))
    if window is None:
        return None
    xs, ys = spec.cell_axes(window)
    free = field_.plannable[window.slices]
    distance = np.where(free, np.hypot(xs - xy[0], ys - xy[1]), np.inf)
    if not np.isfinite(distance).any():
        return None
    r, c = np.unravel_index(int(np.argmin(distance)), distance.shape)
    return (float(xs[0, c]), float(ys[r, 0]))


class _Planner:
    """The replanning policy around ``planner.facade.plan`` (see the module docstring, step 4)."""

    def __init__(self, world: SimWorld, options: RunOptions) -> None:
        self.world, self.options = world, options
        self.path: np.ndarray | None = None
        self.last_plan = -math.inf
        self.plans = self.replans = 0
        self.time_s = 0.0
        self.message = ""
        self.failure: PlanningError | None = None  # why the last plan failed, when the planner refused the task

    def problem(self, costmap: Costmap2D, start: tuple[float, float]) -> PlanningProblem:
        robot = self.world.scenario.robot
        return PlanningProblem(costmap, start, robot.goal[:2], robot.radius, self.options.cost_weight)

    def _call(self, problem: PlanningProblem) -> PlanResult:
        """One ``plan`` call, counted in ``plans`` and seeded by its number."""
        seed = _ompl_seed(self.options.seed, self.plans)
        self.plans += 1
        return plan(problem, self.options.planner, self.options.plan_time_s, seed)

    def _plan(self, costmap: Costmap2D, xy: tuple[float, float]) -> PlanResult | None:
        t0 = time.perf_counter()
        problem = self.problem(costmap, xy)
        start = xy
        self.failure = None
        try:
            result = self._call(problem)
        except PlanningError as exc:
            self.message, self.failure = str(exc), exc
            in_collision = isinstance(exc, EndpointCollisionError) and exc.end == "start"
            escape = _free_start(CostField(problem), xy) if in_collision else None
            if escape is None:
                return None
            start = escape
            try:
                result = self._call(self.problem(costmap, start))
            except PlanningError as again:
                self.message, self.failure = str(again), again
                return None
        finally:  # every call's time, a failed one's too (its endpoint checks, its search until the budget ran out)
            self.time_s += time.perf_counter() - t0
        if not result.success:
            self.message = result.message
            return None
        if start != xy:
            result.path = np.vstack([np.array([xy]), result.path])
        return result

    def update(self, t: float, costmap: Costmap2D, xy: tuple[float, float], radius: float) -> None:
        """Replan when needed and adopt the new path by the policy."""
        blocked = False
        rest = None
        if self.path is not None:
            rest = remaining(self.path, xy, skip=radius)
            # Nav2's test: a sample on an inscribed, lethal or unknown cell (the inflation marks the robot radius).
            costs = costmap.cost_at(interpolate(rest, costmap.spec.resolution / 2))
            blocked = bool((costs >= INSCRIBED).any())
        due = t - self.last_plan >= self.options.replan_period_s - 1e-9
        if not (due or blocked):  # without a path, retry at the periodic rate
            return
        self.last_plan = t
        result = self._plan(costmap, xy)
        if result is None:
            if blocked:
                self.path = None  # nothing safe to follow: wait and retry
            return
        if self.path is None or blocked:
            adopt = True
        else:
            assert rest is not None
            old = CostField(self.problem(costmap, xy)).path_cost(np.vstack([np.array([xy]), rest]))
            adopt = result.cost < (1.0 - self.options.replan_gain) * old
        if adopt:
            if self.path is not None:
                self.replans += 1
            self.path = result.path


def simulate(
    world: SimWorld, options: RunOptions = RunOptions(), observer: Observer | None = None, color: bool = False
) -> RunTrace:
    """Run the closed loop on ``world`` (see the module docstring); ``observer`` sees every step; ``color``: render
    the camera's colour image too (see ``make_sensing``)."""
    world = jittered(world, options.seed)
    scenario, settings = world.scenario, world.settings
    limits = settings.limits
    dt = 1.0 / settings.rate_hz
    control_steps = math.ceil(dt / MAX_CONTROL_PERIOD_S - 1e-9)
    walls = map_walls(scenario)  # read once: the world's collisions and scans, exact perception's sight lines
    sensing = make_sensing(world, options, color, walls)
    planner = _Planner(world, options)
    trace = RunTrace(False, "", 0, 0.0)
    if not options.unknown_map:
        try:
            check_endpoints(CostField(planner.problem(sensing.costmap.master, scenario.robot.start[:2])))
        except PlanningError as exc:
            trace.reason = f"the known map makes the task impossible: {exc}"
            x, y, yaw = scenario.robot.start
            trace.trajectory.append((0.0, x, y, yaw))
            return trace
    obstacles = obstacle_geometry(scenario.obstacles, walls)
    sight = scenario_walls(scenario)  # the true groups: nobody talks through a wall
    lidar, goal = scenario.lidar, scenario.robot.goal
    state = RobotState(*scenario.robot.start)
    follower = FollowerParams(max_speed=limits.max_speed, max_turn_rate=limits.max_turn_rate)
    k = 0
    before: tuple[tuple[float, float], list[Person]] | None = None  # the robot and the people one step earlier
    while True:
        t = k * dt
        people = world.people_at(t)
        truth_groups = scenario_groups(scenario, people, sight)
        trace.trajectory.append((t, state.x, state.y, state.yaw))
        trace.truth.append((people, truth_groups))
        trace.time_s = t
        hit = collision((state.x, state.y), limits.radius, obstacles, people, lidar.body_radius, before)
        if hit is not None:
            trace.collisions, trace.reason = 1, _collision_reason(hit, t, k, state, scenario.walks)
            break
        if math.hypot(goal[0] - state.x, goal[1] - state.y) <= settings.goal_tolerance_m:
            trace.success, trace.reason = True, f"goal reached at t = {t:.1f} s"
            break
        if t >= settings.time_limit_s - 1e-9:
            why = f": {planner.message}" if planner.path is None and planner.message else ""
            if why and planner.failure is not None:  # who is in the way, where they truly stand (the robot saw them)
                problem = planner.problem(sensing.costmap.master, (state.x, state.y))
                blame = people_in_the_way(planner.failure, replace(scenario, people=people), problem)
                why += f"; {blame}" if blame else ""
            trace.reason = f"time limit ({settings.time_limit_s:g} s) reached{why}"
            break
        pose = RobotPose(state.x, state.y, state.yaw)
        scan = simulate_scan(state.pose, scenario.obstacles, people, beams=lidar.beams,
                             range_max=lidar.range_max, body_radius=lidar.body_radius, static=walls)  # fmt: skip
        seen = sensing(k, pose, people, scan)
        planner.update(t, sensing.costmap.master, (state.x, state.y), limits.radius)
        if observer is not None:
            observer(
                StepView(
                    t, state, people, seen.people, seen.groups, scan, sensing.costmap.master, planner.path, seen.image
                )
            )
        before = ((state.x, state.y), people)
        for _ in range(control_steps):  # the follower at its own rate, at most MAX_CONTROL_PERIOD_S apart
            linear, angular = 0.0, 0.0  # without a path the robot waits
            if planner.path is not None:
                command = follow(planner.path, state.pose, state.v, follower)
                linear, angular = command.linear, command.angular
            state = step(state, linear, angular, dt / control_steps, limits)
        k += 1
    trace.plans, trace.replans, trace.planning_time_s = planner.plans, planner.replans, planner.time_s
    return trace
