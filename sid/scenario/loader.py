"""Scenario records: a map, obstacles, people and a robot task, in the world frame (metres, radians).

The file format (JSON or YAML) and its loader live here too; every field and default is documented in
docs/scenario.md ("Scenario file"). A malformed file raises ``ScenarioError`` naming the field.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from collections.abc import Set as AbstractSet
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from costmap.grid import GridSpec
from costmap.layers.inflation import InflationParams
from costmap.layers.obstacle import ObstacleParams
from costmap.layers.social import SocialParams
from costmap.mapfile import MapFileError, read_map
from costmap.plugins import PLUGINS, CostmapParams
from sid.documents import is_number, load_document
from sid.perception.groups import GroupParams
from sid.perception.people import Person
from sid.scenario.obstacles import BoxObstacle, CircleObstacle, Obstacle, SegmentObstacle

__all__ = [
    "BoxObstacle",
    "CircleObstacle",
    "CostmapParams",
    "LidarSpec",
    "Obstacle",
    "RobotSpec",
    "Scenario",
    "ScenarioError",
    "SegmentObstacle",
    "load_scenario",
    "scenario_from_dict",
]


@dataclass(frozen=True)
class RobotSpec:
    """Start and goal poses (x, y, yaw) and the radius of the robot's disc footprint."""

    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    radius: float = 0.25


@dataclass(frozen=True)
class LidarSpec:
    """A simulated 2D LiDAR at the robot's start pose: beam count, max range (m), scan height (m).

    body_radius: a person's cross-section at the scan height (m), a circle the beams hit. Obstacles and people
    are vertical prisms through the scan plane, so ``height`` documents the plane and changes no range.
    """

    beams: int = 720
    range_max: float = 10.0
    height: float = 0.3
    body_radius: float = 0.2


@dataclass
class Scenario:
    name: str
    grid: GridSpec
    robot: RobotSpec
    obstacles: list[Obstacle] = field(default_factory=list)
    people: list[Person] = field(default_factory=list)
    lidar: LidarSpec = field(default_factory=LidarSpec)
    static_map: Path | None = None
    group_params: GroupParams = field(default_factory=GroupParams)
    layers: CostmapParams = field(default_factory=CostmapParams)


class ScenarioError(ValueError):
    """A scenario file or mapping that cannot be used; the message names the offending field."""


# --- field readers: each takes the value and its dotted field name, returns a clean value or raises ---------


def _fail(name: str, expected: str, value: Any) -> ScenarioError:
    return ScenarioError(f"{name}: expected {expected}, got {value!r}")


def _number(value: Any, name: str, *, positive: bool = False, minimum: float | None = None) -> float:
    if not is_number(value):
        raise _fail(name, "a finite number", value)
    if positive and value <= 0:
        raise _fail(name, "a positive number", value)
    if minimum is not None and value < minimum:
        raise _fail(name, f"a number >= {minimum}", value)
    return float(value)


def _integer(value: Any, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise _fail(name, f"an integer >= {minimum}", value)
    return value


def _point(value: Any, name: str, sizes: tuple[int, ...] = (2,)) -> tuple[float, ...]:
    if not isinstance(value, list | tuple) or len(value) not in sizes:
        raise _fail(name, " or ".join(f"a list of {n} numbers" for n in sizes), value)
    return tuple(_number(v, f"{name}[{i}]") for i, v in enumerate(value))


def _xy(value: Any, name: str) -> tuple[float, float]:
    x, y = _point(value, name)
    return (x, y)


def _mapping(value: Any, name: str, known: AbstractSet[str], required: AbstractSet[str] = frozenset()) -> dict:
    if not isinstance(value, dict):
        raise _fail(name, "a mapping", value)
    unknown = sorted(set(value) - known)
    if unknown:
        raise ScenarioError(f"{name}.{unknown[0]}: unknown field; known fields: {', '.join(sorted(known))}")
    missing = sorted(required - set(value))
    if missing:
        raise ScenarioError(f"{name}.{missing[0]}: required field is missing")
    return value


def _list(value: Any, name: str) -> list:
    if not isinstance(value, list):
        raise _fail(name, "a list", value)
    return value


def _params(value: Any, name: str, cls: type) -> Any:
    """A parameter dataclass from a mapping of its fields, typed by the defaults (bool, int or float)."""
    defaults = {f.name: getattr(cls(), f.name) for f in dataclasses.fields(cls)}
    data = _mapping(value, name, set(defaults))
    kwargs: dict[str, Any] = {}
    for key, raw in data.items():
        default, key_name = defaults[key], f"{name}.{key}"
        if isinstance(default, bool):
            if not isinstance(raw, bool):
                raise _fail(key_name, "true or false", raw)
            kwargs[key] = raw
        elif isinstance(default, int):
            kwargs[key] = _integer(raw, key_name, 0)
        else:
            kwargs[key] = _number(raw, key_name)
    try:
        return cls(**kwargs)
    except ValueError as exc:
        raise ScenarioError(f"{name}: {exc}") from exc


def _plugins(value: Any, name: str) -> tuple[str, ...]:
    """Layer names in combination order, each a key of ``costmap.plugins.PLUGINS``."""
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise _fail(name, "a list of layer names", value)
    for i, layer in enumerate(value):
        if layer not in PLUGINS:
            raise ScenarioError(f"{name}[{i}]: unknown layer {layer!r}; known layers: {', '.join(PLUGINS)}")
    return tuple(value)


# --- sections -----------------------------------------------------------------------------------------------


def _grid(value: Any, static: GridSpec | None) -> GridSpec:
    if value is None:
        if static is None:
            raise ScenarioError("map: required field is missing (or give static_map to take its geometry)")
        return static
    data = _mapping(value, "map", {"resolution", "origin", "size"}, {"size"})
    resolution = _number(data.get("resolution", 0.05), "map.resolution", positive=True)
    origin = _point(data.get("origin", [0.0, 0.0]), "map.origin", (2, 3))
    if len(origin) == 3 and origin[2] != 0:
        raise ScenarioError(f"map.origin: a rotated map is not supported (yaw {origin[2]}); use yaw 0")
    width, height = (_number(v, f"map.size[{i}]", positive=True) for i, v in enumerate(_xy(data["size"], "map.size")))
    size = (width, height)
    if min(size) < resolution:
        raise ScenarioError(f"map.size: {size} m is smaller than one {resolution} m cell")
    return GridSpec.from_size(resolution, (origin[0], origin[1]), size)


def _obstacle(value: Any, name: str) -> Obstacle:
    if not isinstance(value, dict) or "type" not in value:
        raise _fail(name, 'a mapping with a "type" (segment, circle or box)', value)
    kind = value["type"]
    if kind == "segment":
        data = _mapping(value, name, {"type", "points"}, {"points"})
        points = _list(data["points"], f"{name}.points")
        if len(points) < 2:
            raise _fail(f"{name}.points", "at least 2 points", points)
        return SegmentObstacle(tuple(_xy(p, f"{name}.points[{i}]") for i, p in enumerate(points)))
    if kind == "circle":
        data = _mapping(value, name, {"type", "center", "radius"}, {"center", "radius"})
        radius = _number(data["radius"], f"{name}.radius", positive=True)
        return CircleObstacle(_xy(data["center"], f"{name}.center"), radius)
    if kind == "box":
        data = _mapping(value, name, {"type", "min", "max"}, {"min", "max"})
        lo, hi = _xy(data["min"], f"{name}.min"), _xy(data["max"], f"{name}.max")
        if not (lo[0] < hi[0] and lo[1] < hi[1]):
            raise ScenarioError(f"{name}: min {lo} must be below max {hi} in x and y")
        return BoxObstacle(lo, hi)
    raise _fail(f"{name}.type", '"segment", "circle" or "box"', kind)


def _person(value: Any, name: str, index: int) -> Person:
    data = _mapping(value, name, {"id", "x", "y", "theta", "orientation_quality"}, {"x", "y"})
    pid = _integer(data.get("id", index + 1), f"{name}.id", 0)
    x, y = _number(data["x"], f"{name}.x"), _number(data["y"], f"{name}.y")
    theta = data.get("theta")
    if theta is not None:
        if not is_number(theta):
            raise _fail(f"{name}.theta", "a finite number of radians, or null when unknown", theta)
        theta = float(theta)
    quality = _number(data.get("orientation_quality", 0.0 if theta is None else 1.0), f"{name}.orientation_quality")
    if not 0 <= quality <= 1:
        raise _fail(f"{name}.orientation_quality", "a number in [0, 1]", quality)
    return Person(pid, x, y, theta, quality)


def _pose(value: Any, name: str) -> tuple[float, float, float]:
    pose = _point(value, name, (2, 3))
    return (pose[0], pose[1], pose[2] if len(pose) == 3 else 0.0)


def _inside(grid: GridSpec, xy: tuple[float, ...], name: str) -> None:
    if not grid.contains(np.array([xy[:2]]))[0]:
        x0, y0, x1, y1 = grid.bounds
        raise ScenarioError(f"{name}: ({xy[0]}, {xy[1]}) is outside the map (x {x0:g}..{x1:g}, y {y0:g}..{y1:g})")


TOP_LEVEL = {"name", "map", "obstacles", "static_map", "people", "robot", "lidar", "groups", "layers"}


def scenario_from_dict(data: Any, base_dir: Path | None = None, default_name: str = "scenario") -> Scenario:
    """A Scenario from a parsed JSON/YAML mapping; ``static_map`` is relative to ``base_dir`` (default cwd)."""
    data = _mapping(data, "scenario", TOP_LEVEL, {"robot"})
    name = data.get("name", default_name)
    if not isinstance(name, str) or not name:
        raise _fail("name", "a non-empty string", name)

    static_map, static_spec = None, None
    if data.get("static_map") is not None:
        raw = data["static_map"]
        if not isinstance(raw, str) or not raw:
            raise _fail("static_map", "a path to a map_server YAML file", raw)
        static_map = Path(raw) if Path(raw).is_absolute() or base_dir is None else base_dir / raw
        try:
            static_spec = read_map(static_map).spec
        except MapFileError as exc:
            raise ScenarioError(f"static_map: {exc}") from exc
    grid = _grid(data.get("map"), static_spec)

    obstacles = [_obstacle(o, f"obstacles[{i}]") for i, o in enumerate(_list(data.get("obstacles", []), "obstacles"))]
    people = [_person(p, f"people[{i}]", i) for i, p in enumerate(_list(data.get("people", []), "people"))]
    seen: dict[int, int] = {}
    for i, person in enumerate(people):
        if person.id in seen:
            raise ScenarioError(f"people[{i}].id: {person.id} is already used by people[{seen[person.id]}]")
        seen[person.id] = i
        _inside(grid, (person.x, person.y), f"people[{i}]")

    robot_data = _mapping(data["robot"], "robot", {"start", "goal", "radius"}, {"start", "goal"})
    robot = RobotSpec(
        _pose(robot_data["start"], "robot.start"),
        _pose(robot_data["goal"], "robot.goal"),
        _number(robot_data.get("radius", RobotSpec.radius), "robot.radius", positive=True),
    )
    _inside(grid, robot.start, "robot.start")
    _inside(grid, robot.goal, "robot.goal")

    lidar_data = _mapping(data.get("lidar", {}), "lidar", {f.name for f in dataclasses.fields(LidarSpec)})
    defaults = LidarSpec()
    lidar = LidarSpec(
        _integer(lidar_data.get("beams", defaults.beams), "lidar.beams", 1),
        _number(lidar_data.get("range_max", defaults.range_max), "lidar.range_max", positive=True),
        _number(lidar_data.get("height", defaults.height), "lidar.height", minimum=0.0),
        _number(lidar_data.get("body_radius", defaults.body_radius), "lidar.body_radius", positive=True),
    )

    layer_sections: dict[str, Callable[[Any, str], Any]] = {
        "plugins": _plugins,
        "obstacle": lambda v, n: _params(v, n, ObstacleParams),
        "inflation": lambda v, n: _params(v, n, InflationParams),
        "social": lambda v, n: _params(v, n, SocialParams),
    }
    layers_data = _mapping(data.get("layers", {}), "layers", set(layer_sections))
    sections = {k: layer_sections[k](v, f"layers.{k}") for k, v in layers_data.items()}
    try:
        layers = CostmapParams(**sections)
    except ValueError as exc:
        raise ScenarioError(f"layers.{exc}") from exc

    return Scenario(
        name=name,
        grid=grid,
        robot=robot,
        obstacles=obstacles,
        people=people,
        lidar=lidar,
        static_map=static_map,
        group_params=_params(data.get("groups", {}), "groups", GroupParams),
        layers=layers,
    )


def load_scenario(path: str | Path) -> Scenario:
    """Read a scenario file (.json, or YAML for any other suffix); errors name the file and the field."""
    path = Path(path)
    try:
        data = load_document(path, "scenario file")
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None
    try:
        return scenario_from_dict(data, base_dir=path.parent, default_name=path.stem)
    except ScenarioError as exc:
        raise ScenarioError(f"{path}: {exc}") from exc
