"""The simulated world: a scenario (map, obstacles, people and their scripted walks, robot task), the robot's limits and
the run's settings, read from one scenario file; and the ground-truth geometry the simulation measures against.

A simulation file is a scenario file (docs/scenario.md: people may walk along ``people[i].path``) with one more,
optional block, ``simulation``: ``max_speed`` (m/s, 0.5), ``max_turn_rate`` (rad/s, 1.5), ``max_accel`` (m/s^2,
1.0), ``time_limit_s`` (60), ``rate_hz`` (10), ``goal_tolerance_m`` (0.25), ``description`` (text for ``--list``).
Every person who stands (no ``path``) needs a ``theta``: the world is ground truth, and the camera renders each body
from its facing. For the same reason nobody may stand inside an obstacle or walk through one, or stand with their
centre inside another's body at time 0; a body that only overlaps a wall or another body is warned of.

Seeds (``jittered``): seed 0 is the scene as written; seed k >= 1 moves every standing person by Gaussian jitter of
``JITTER_XY_M`` and turns them by ``JITTER_THETA_RAD`` (drawn from ``[k, 7]``), so that sweeps over seeds see
slightly different conversations, as real people never stand twice alike.

World frame = the map frame (REP-103), metres, radians, seconds.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace
from itertools import combinations
from pathlib import Path
from typing import Any

import numpy as np
from shapely.geometry import LineString, Point, box
from shapely.ops import unary_union

from costmap.grid import LETHAL, Costmap2D
from sid.checks import LimitError, check_limit
from sid.documents import InputWarning, is_number, summary
from sid.experiments.simulate.robot import DriveLimits
from sid.perception.people import Person
from sid.scenario.build import map_walls
from sid.scenario.loader import Scenario, ScenarioError, read_scenario_file, scenario_from_dict
from sid.scenario.obstacles import Obstacle, shape

__all__ = [
    "JITTER_THETA_RAD",
    "JITTER_XY_M",
    "RATE_HZ",
    "TOUCH_M",
    "SIM_FIELDS",
    "SimSettings",
    "SimWorld",
    "closest_approach",
    "collision",
    "jittered",
    "load_world",
    "obstacle_geometry",
    "world_from_dict",
]

JITTER_XY_M = 0.05
JITTER_THETA_RAD = math.radians(5.0)
TOUCH_M = 1e-6
"""How far (m) a body may reach into an obstacle or another body and still count as touching it (a person drawn with
their back to a wall, ``body_radius`` from it, lies a rounding error nearer)."""
RATE_HZ = (0.1, 1000.0)
"""The range of ``simulation.rate_hz`` (Hz): steps per second and run.mp4's frame rate, which OpenCV's mp4v writer
cannot open at 1e-3 or 1e5 frames per second."""
SIM_FIELDS = ("max_speed", "max_turn_rate", "max_accel", "time_limit_s", "rate_hz", "goal_tolerance_m", "description")


@dataclass(frozen=True)
class SimSettings:
    """Per-scene settings of a run: the robot's limits, time limit (s), control rate (Hz), goal tolerance (m)."""

    limits: DriveLimits = field(default_factory=DriveLimits)
    time_limit_s: float = 60.0
    rate_hz: float = 10.0
    goal_tolerance_m: float = 0.25
    description: str = ""


@dataclass
class SimWorld:
    """A scenario (``people`` at time 0, ``walks``: their scripted motion) and the run's settings."""

    scenario: Scenario
    settings: SimSettings

    def people_at(self, t: float) -> list[Person]:
        """Every person's true pose at time ``t`` (s): standing, or walking and facing the way they go."""
        people = []
        for p in self.scenario.people:
            if p.id not in self.scenario.walks:
                people.append(p)
                continue
            state = self.scenario.walks[p.id].at(t)
            people.append(Person(p.id, state.x, state.y, state.yaw, 0.0 if state.yaw is None else 1.0))
        return people


def jittered(world: SimWorld, seed: int) -> SimWorld:
    """The world of ``seed`` (see the module docstring): the same world for seed 0."""
    if seed == 0:
        return world
    rng = np.random.default_rng([seed, 7])
    people = []
    for p in world.scenario.people:
        dx, dy, turn = rng.normal(0.0, [JITTER_XY_M, JITTER_XY_M, JITTER_THETA_RAD])
        if p.id in world.scenario.walks:
            people.append(p)
            continue
        theta = None if p.theta is None else math.remainder(p.theta + turn, math.tau)
        people.append(Person(p.id, p.x + dx, p.y + dy, theta, p.orientation_quality))
    return SimWorld(replace(world.scenario, people=people), world.settings)


def _fail(name: str, expected: str, value: Any) -> ScenarioError:
    return ScenarioError(f"{name}: expected {expected}, got {summary(value)}")


def _settings(data: dict[str, Any]) -> SimSettings:
    unknown = sorted(set(data) - set(SIM_FIELDS))
    if unknown:
        raise ScenarioError(f"simulation.{unknown[0]}: unknown field; known fields: {', '.join(SIM_FIELDS)}")
    for key, value in data.items():
        if key != "description" and (not is_number(value) or value <= 0):
            raise _fail(f"simulation.{key}", "a positive number", value)
    rate = data.get("rate_hz", SimSettings.rate_hz)
    if not RATE_HZ[0] <= rate <= RATE_HZ[1]:  # also run.mp4's frame rate: OpenCV's mp4v writer fails outside
        raise _fail("simulation.rate_hz", f"a number of Hz in [{RATE_HZ[0]:g}, {RATE_HZ[1]:g}]", rate)
    description = data.get("description", "")
    if not isinstance(description, str):
        raise _fail("simulation.description", "a string", description)
    limits = {k: float(data[k]) for k in ("max_speed", "max_turn_rate", "max_accel") if k in data}
    numbers = {k: float(data[k]) for k in ("time_limit_s", "rate_hz", "goal_tolerance_m") if k in data}
    settings = SimSettings(limits=DriveLimits(**limits), description=description, **numbers)
    steps = settings.time_limit_s * settings.rate_hz  # the run keeps every step's people and pose
    detail = f"{settings.time_limit_s:g} s x {settings.rate_hz:g} Hz = "
    try:
        check_limit("simulation", steps, "sim_steps", "steps", detail)
    except LimitError as exc:
        raise ScenarioError(str(exc)) from None
    return settings


def world_from_dict(data: Any, base_dir: Path | None = None, default_name: str = "scenario") -> SimWorld:
    """A SimWorld from a parsed simulation file (see the module docstring); errors name the field."""
    scenario = scenario_from_dict(data, base_dir, default_name)  # also checks that ``simulation`` is a mapping
    settings = _settings(data.get("simulation", {}))
    for i, person in enumerate(scenario.people):
        if person.theta is None and person.id not in scenario.walks:
            raise ScenarioError(
                f"people[{i}].theta: a simulated standing person needs a facing (radians): the camera renders their "
                "body from it; an unknown facing is what perception reports, not part of the world"
            )
    _check_bodies(scenario)
    return SimWorld(scenario, replace(settings, limits=replace(settings.limits, radius=scenario.robot.radius)))


def _check_bodies(scenario: Scenario) -> None:
    """Refuse a world in which a person stands inside an obstacle (or the ``static_map`` file's walls), walks through
    one, or stands with their centre inside another person's body (``lidar.body_radius``) at time 0: the scene is the
    true world, and the robot would see, plan round and collide with bodies no one could have. A body that only
    overlaps a wall or another body is warned of: the body is a disc, and real people stand closer than two of them.
    """
    body = scenario.lidar.body_radius
    named = [(f"obstacles[{j}]", shape(obstacle)) for j, obstacle in enumerate(scenario.obstacles)]
    walls = map_walls(scenario)
    if walls is not None and (walls.costs == LETHAL).any():
        named.append(("the static_map file's walls", obstacle_geometry([], walls)))
    for i, person in enumerate(scenario.people):
        walk = scenario.walks.get(person.id)
        where = Point(person.x, person.y) if walk is None else LineString([(walk.x, walk.y), *walk.path])
        what = f"stands at ({person.x:.2f}, {person.y:.2f})" if walk is None else "walks along its path"
        for name, geometry in named:
            gap = geometry.distance(where)
            if gap == 0.0:
                raise ScenarioError(f"people[{i}]: person {person.id} {what} on or inside {name}")
            if gap < body - TOUCH_M:
                warnings.warn(
                    f"people[{i}]: person {person.id} {what} {gap:.2f} m from {name}: a body of radius {body:.2f} m "
                    "(lidar.body_radius) overlaps it",
                    InputWarning,
                    stacklevel=3,
                )
    for (i, a), (j, b) in combinations(enumerate(scenario.people), 2):
        gap = math.hypot(a.x - b.x, a.y - b.y)
        if gap >= 2 * body - TOUCH_M:
            continue
        between = f"people[{j}]: person {b.id} at ({b.x:.2f}, {b.y:.2f}) is {gap:.2f} m from person {a.id}"
        between += f" (people[{i}])"
        if gap < body - TOUCH_M:
            raise ScenarioError(f"{between} at time 0: inside their body (lidar.body_radius {body:.2f} m)")
        warnings.warn(
            f"{between} at time 0: two bodies of radius {body:.2f} m (lidar.body_radius) overlap",
            InputWarning,
            stacklevel=3,
        )


def load_world(path: str | Path) -> SimWorld:
    """Read a simulation (or plain scenario) file; errors name the file and the field."""
    return read_scenario_file(path, world_from_dict)


# --- ground-truth geometry -------------------------------------------------------------------------------------


def obstacle_geometry(obstacles: list[Obstacle], walls: Costmap2D | None = None) -> Any:
    """The declared obstacles as one shapely geometry (walls as lines, boxes and circles as areas), with the LETHAL
    cells of ``walls`` (a static map file's, ``sid.scenario.build.map_walls``) as squares, merged along each row."""
    shapes: list[Any] = []
    if walls is not None:
        spec, lethal = walls.spec, walls.costs == LETHAL
        for row in np.flatnonzero(lethal.any(axis=1)):
            edges = np.flatnonzero(np.diff(np.concatenate([[0], lethal[row].view(np.int8), [0]])))
            y0 = spec.origin_y + row * spec.resolution
            for c0, c1 in zip(edges[::2], edges[1::2], strict=True):
                x0, x1 = spec.origin_x + c0 * spec.resolution, spec.origin_x + c1 * spec.resolution
                shapes.append(box(x0, y0, x1, y0 + spec.resolution))
    shapes.extend(shape(ob) for ob in obstacles)
    return unary_union(shapes) if shapes else None


def collision(
    xy: tuple[float, float],
    radius: float,
    obstacles: Any,
    people: list[Person],
    body_radius: float,
    before: tuple[tuple[float, float], list[Person]] | None = None,
) -> str | None:
    """What the robot's disc (centre ``xy``, ``radius``) overlaps: "obstacle", "person N", or None. With ``before``
    (the robot's centre and the people one step earlier), over the whole step: the robot and each person moving
    straight from there (``closest_approach``), so that a walker who crosses the robot between two steps (a low
    ``rate_hz``) is not missed."""
    if before is None:
        reach: Any = Point(xy)
        gaps = {p.id: math.hypot(p.x - xy[0], p.y - xy[1]) for p in people}
    else:
        start, earlier = before
        reach = LineString([start, xy]) if start != xy else Point(xy)
        gaps = dict(zip((p.id for p in people), closest_approach(start, xy, earlier, people).tolist(), strict=True))
    if obstacles is not None and obstacles.distance(reach) < radius:
        return "obstacle"
    for p in people:
        if gaps[p.id] < radius + body_radius:
            return f"person {p.id}"
    return None


def closest_approach(
    start: tuple[float, float], end: tuple[float, float], earlier: list[Person], people: list[Person]
) -> np.ndarray:
    """(N,) the least distance (m) between the robot, moving straight from ``start`` to ``end`` over a step, and each
    of ``people``, moving straight from where ``earlier`` (the same ids, one step before) had them; a person not in
    ``earlier`` is taken as standing. Relative motion is linear, so the least distance has a closed form."""
    then = {p.id: (p.x, p.y) for p in earlier}
    now = np.array([(p.x, p.y) for p in people], dtype=float).reshape(-1, 2)
    before = np.array([then.get(p.id, (p.x, p.y)) for p in people], dtype=float).reshape(-1, 2)
    r0 = before - np.asarray(start, dtype=float)  # person from robot, at the step's start and end
    dr = now - np.asarray(end, dtype=float) - r0
    moved = np.einsum("ij,ij->i", dr, dr)
    s = np.clip(-np.einsum("ij,ij->i", r0, dr) / np.where(moved > 0, moved, 1.0), 0.0, 1.0)
    return np.hypot(*(r0 + s[:, None] * dr).T)
