"""Scenario records: a map, obstacles, people and a robot task, in the world frame (metres, radians).

The file format (JSON or YAML) and its loader live here too; every field and default is documented in
docs/scenario.md ("Scenario file"). A malformed file raises ``ScenarioError`` naming the field.
"""

from __future__ import annotations

import dataclasses
import math
import re
import warnings
from collections.abc import Callable
from collections.abc import Set as AbstractSet
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
from shapely.geometry import box

from costmap.grid import BORDER_TOLERANCE, GridSpec
from costmap.layers.inflation import check_reach
from costmap.mapfile import MapFileError, read_map
from costmap.occupancy import OccupancyGrid
from costmap.plugins import PEOPLE_LAYERS, PLUGINS, SECTIONS, CostmapParams, LayerInstance
from sid.checks import LimitError, amount, check_limit, check_yaw
from sid.documents import InputWarning, is_number, load_document, summary
from sid.errors import SidError
from sid.perception.groups import GroupParams
from sid.perception.people import Person
from sid.scenario.known_map import obstacle_mask
from sid.scenario.motion import Trajectory
from sid.scenario.obstacles import BoxObstacle, CircleObstacle, Obstacle, SegmentObstacle, shape

__all__ = [
    "BoxObstacle",
    "CircleObstacle",
    "CostmapParams",
    "LidarSpec",
    "Obstacle",
    "PERSON_FIELDS",
    "RobotSpec",
    "Scenario",
    "ScenarioError",
    "SegmentObstacle",
    "TOP_LEVEL",
    "layers_from_dict",
    "load_scenario",
    "params_from_dict",
    "read_scenario_file",
    "scenario_from_dict",
]


@dataclass(frozen=True)
class RobotSpec:
    """Start and goal poses (x, y, yaw) and the radius of the robot's disc footprint (m).

    path / speed: waypoints (map frame, m) the robot drives through from ``start`` at ``speed`` (m/s), facing its
    direction of travel (synthetic scenes: the camera's motion); no path = it stays at ``start``.
    """

    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    radius: float = 0.25
    path: tuple[tuple[float, float], ...] = ()
    speed: float = 0.5

    @property
    def trajectory(self) -> Trajectory:
        """The pose of ``base_footprint`` in the map over time (``sid.scenario.motion``)."""
        x, y, yaw = self.start
        return Trajectory(x, y, yaw, self.path, self.speed)


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
    """A navigation task (see docs/scenario.md). ``people`` stand where the file puts them (their start poses);
    ``walks``: person id -> scripted motion of the people that walk (``people[i].path``); ``conversations``:
    declared conversational groups (person ids), the ground truth of synthetic scenes."""

    name: str
    grid: GridSpec
    robot: RobotSpec
    obstacles: list[Obstacle] = field(default_factory=list)
    people: list[Person] = field(default_factory=list)
    lidar: LidarSpec = field(default_factory=LidarSpec)
    static_map: Path | None = None
    group_params: GroupParams = field(default_factory=GroupParams)
    layers: CostmapParams = field(default_factory=CostmapParams)
    walks: dict[int, Trajectory] = field(default_factory=dict)
    conversations: tuple[tuple[int, ...], ...] = ()

    def trajectory(self, person: Person) -> Trajectory:
        """The motion of ``person`` (one of ``people``): its walk, or standing still at its position."""
        return self.walks.get(person.id) or Trajectory(person.x, person.y, person.theta)


class ScenarioError(SidError, ValueError):
    """A scenario file or mapping that cannot be used; the message names the offending field."""


# --- field readers: each takes the value and its dotted field name, returns a clean value or raises ---------


def _fail(name: str, expected: str, value: Any) -> ScenarioError:
    return ScenarioError(f"{name}: expected {expected}, got {summary(value)}")


def _number(value: Any, name: str, *, positive: bool = False, minimum: float | None = None) -> float:
    if not is_number(value):
        raise _fail(name, "a finite number", value)
    if positive and value <= 0:
        raise _fail(name, "a positive number", value)
    if minimum is not None and value < minimum:
        raise _fail(name, f"a number >= {minimum}", value)
    return float(value)


def _length(value: Any, name: str, grid: GridSpec) -> float:
    """A positive length (m) at most the map's diagonal: a radius beyond it covers the whole map anyway, and the
    drawing and ray arithmetic downstream need numbers of the map's size."""
    length = _number(value, name, positive=True)
    reach = math.hypot(*grid.size_m)
    if length > reach:
        raise ScenarioError(f"{name}: {length:g} m is more than the map's diagonal ({reach:g} m); use at most that")
    return length


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


def _mapping(
    value: Any, name: str, known: AbstractSet[str], required: AbstractSet[str] = frozenset()
) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise _fail(name, "a mapping", value)
    unknown = sorted(str(key) for key in set(value) - known)  # str: YAML reads `1:` as a number key
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


def params_from_dict(value: Any, name: str, cls: type) -> Any:
    """A parameter dataclass ``cls`` from a mapping (the block ``name`` of a file) of some of its fields, typed by
    the defaults (bool, int, float or str; a field whose default is itself such a dataclass is a block of its own,
    ``tracking.tracker``); the others keep their defaults. A float field may be ``.inf`` where the record takes it
    (``GroupParams.meeting_radius``). ScenarioError naming the field."""
    defaults = {f.name: getattr(cls(), f.name) for f in dataclasses.fields(cls)}
    data = _mapping(value, name, set(defaults))
    kwargs: dict[str, Any] = {}
    for key, raw in data.items():
        default, key_name = defaults[key], f"{name}.{key}"
        if dataclasses.is_dataclass(default):
            kwargs[key] = params_from_dict(raw, key_name, type(default))
        elif isinstance(default, bool):
            if not isinstance(raw, bool):
                raise _fail(key_name, "true or false", raw)
            kwargs[key] = raw
        elif isinstance(default, int):
            kwargs[key] = _integer(raw, key_name, 0)
        elif isinstance(default, str):  # a choice, e.g. groups.method; the record names the accepted values
            if not isinstance(raw, str):
                raise _fail(key_name, "a string", raw)
            kwargs[key] = raw
        elif raw == math.inf and not isinstance(raw, bool):  # YAML's .inf: a switch-off value the record may take
            kwargs[key] = math.inf
        else:
            kwargs[key] = _number(raw, key_name)
    try:
        return cls(**kwargs)
    except ValueError as exc:  # "groups: method must be ...": the dataclass's own name gives way to the block's path
        reason = re.sub(r"^[a-z]+(?: [a-z]+)?: ", "", str(exc), count=1)  # "groups: ", "group tracker: "
        raise ScenarioError(f"{name}: {reason}") from exc


def _plugins(value: Any, where: str, declared: dict[str, str]) -> tuple[str, ...]:
    """Layer instance names in combination order (``WHERE.plugins``): each a key of ``costmap.plugins.PLUGINS`` (an
    instance of that plugin) or a name ``declared`` with its plugin (``WHERE.NAME.plugin``); at least one of them a
    layer that marks people (the LiDAR's or a people layer): without one the robot would plan through them."""
    name = f"{where}.plugins"
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise _fail(name, "a list of layer names", value)
    for i, layer in enumerate(value):
        if layer not in PLUGINS and layer not in declared:
            raise ScenarioError(
                f"{name}[{i}]: unknown layer {summary(layer)}; known layers: {', '.join(PLUGINS)}, or a name of "
                f"your own declared as {where}.{layer}: {{plugin: ...}}"
            )
    marking = ("lidar", *sorted(PEOPLE_LAYERS))
    if not {declared.get(v, v) for v in value} & set(marking):
        raise ScenarioError(f"{name}: {value} has no layer that marks people; list one of {', '.join(marking)}")
    return tuple(value)


_SECTION_TYPES: dict[str, type] = {section: type(getattr(CostmapParams(), section)) for section in SECTIONS.values()}
"""The ``layers`` sections of each plugin's default parameters (``costmap.plugins.SECTIONS``) and their records."""


def layers_from_dict(
    value: Any, grid: GridSpec, where: str = "layers", lidar: LidarSpec | None = None, edges: int = 0
) -> CostmapParams:
    """The costmap's layers from a mapping (a scenario file's ``layers`` block; the ``sid ros`` node's ``costmap.*``
    parameters): ``plugins``, each plugin's default parameters (``obstacle``, ``inflation``, ``social``,
    ``tracked_people``) and the instances named otherwise than their plugin, ``NAME: {plugin: P, ...P's
    parameters}`` (NAME listed in ``plugins``), as Nav2's costmap declares its layers. Errors name the field as
    ``WHERE.FIELD``. Checked against ``grid``: the simulated scan's size when ``lidar`` feeds the costmap (``edges``:
    what each beam is tested against), and each inflation radius."""
    if not isinstance(value, dict):
        raise _fail(where, "a mapping", value)
    listed = value.get("plugins", list(CostmapParams().plugins))
    names = {v for v in listed if isinstance(v, str) and v not in PLUGINS} if isinstance(listed, list) else set()
    data = _mapping(value, where, {"plugins", *_SECTION_TYPES, *names})
    declared: dict[str, str] = {}
    for key in sorted(names & set(data)):
        field_name = f"{where}.{key}"
        section = _mapping(data[key], field_name, set(data[key]) if isinstance(data[key], dict) else set(), {"plugin"})
        plugin = section["plugin"]
        if not isinstance(plugin, str) or plugin not in PLUGINS:
            known = ", ".join(PLUGINS)
            raise ScenarioError(f"{field_name}.plugin: unknown plugin {summary(plugin)}; known plugins: {known}")
        declared[key] = plugin
    plugins = _plugins(listed, where, declared)
    sections = {
        k: params_from_dict(v, f"{where}.{k}", _SECTION_TYPES[k]) for k, v in data.items() if k in _SECTION_TYPES
    }
    instances = {}
    for key, plugin in declared.items():
        own = {k: v for k, v in data[key].items() if k != "plugin"}
        kind = SECTIONS.get(plugin)
        if kind is None and own:
            raise ScenarioError(f"{where}.{key}: the {plugin} plugin takes no parameters, got {', '.join(own)}")
        params = None if kind is None else params_from_dict(own, f"{where}.{key}", _SECTION_TYPES[kind])
        instances[key] = LayerInstance(plugin, params)
    try:
        layers = CostmapParams(plugins=plugins, instances=instances, **sections)
    except ValueError as exc:
        raise ScenarioError(f"{where}.{exc}") from exc
    if lidar is not None:
        _check_scan(grid, lidar, layers, edges)
    _check_inflation(grid, layers, where)
    return layers


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
    try:
        return GridSpec.from_size(resolution, (origin[0], origin[1]), size)
    except ValueError as exc:  # above Limits.map_cells
        raise ScenarioError(str(exc)) from None


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


PERSON_FIELDS = {"id", "x", "y", "theta", "orientation_quality", "path", "speed", "start_time"}


def _person(value: Any, name: str, index: int) -> Person:
    data = _mapping(value, name, PERSON_FIELDS, {"x", "y"})
    pid = _integer(data.get("id", index + 1), f"{name}.id", 0)
    x, y = _number(data["x"], f"{name}.x"), _number(data["y"], f"{name}.y")
    theta = data.get("theta")
    if theta is not None:
        if not is_number(theta):
            raise _fail(f"{name}.theta", "a finite number of radians, or null when unknown", theta)
        theta = float(theta)
        check_yaw(name, "theta", theta, error=ScenarioError)
    quality = _number(data.get("orientation_quality", 0.0 if theta is None else 1.0), f"{name}.orientation_quality")
    if not 0 <= quality <= 1:
        raise _fail(f"{name}.orientation_quality", "a number in [0, 1]", quality)
    return Person(pid, x, y, theta, quality)


def _path(value: Any, name: str, grid: GridSpec, start: tuple[float, float]) -> tuple[tuple[float, float], ...]:
    """Waypoints [[x, y], ...] inside the map, each different from the point before it (``start`` first)."""
    if not isinstance(value, list) or not value:
        raise _fail(name, "a non-empty list of [x, y] waypoints", value)
    points: list[tuple[float, float]] = []
    for i, raw in enumerate(value):
        point = _xy(raw, f"{name}[{i}]")
        _inside(grid, point, f"{name}[{i}]")
        if points and point == points[-1]:
            raise ScenarioError(f"{name}[{i}]: {list(point)} repeats the point before it")
        if not points and point == start:
            raise ScenarioError(
                f"{name}[0]: {list(point)} repeats the point the path starts from: a path lists the waypoints after it"
            )
        points.append(point)
    return tuple(points)


def _motion(data: dict, name: str, grid: GridSpec, start: tuple[float, float], speed: float) -> dict[str, Any]:
    """``path``, ``speed`` (m/s) and, for people, ``start_time`` (s) of a mover's mapping, checked."""
    if "path" not in data:
        extra = sorted({"speed", "start_time"} & set(data))
        if extra:
            raise ScenarioError(f"{name}.{extra[0]}: only meaningful with a path")
        return {}
    motion: dict[str, Any] = {
        "path": _path(data["path"], f"{name}.path", grid, start),
        "speed": _number(data.get("speed", speed), f"{name}.speed", positive=True),
    }
    if "start_time" in data:
        motion["start_time"] = _number(data["start_time"], f"{name}.start_time", minimum=0.0)
    return motion


def _walk(value: dict, name: str, grid: GridSpec, person: Person) -> Trajectory | None:
    motion = _motion(value, name, grid, (person.x, person.y), Trajectory.speed)
    return Trajectory(person.x, person.y, person.theta, **motion) if motion else None


def _conversations(value: Any, people: list[Person]) -> tuple[tuple[int, ...], ...]:
    """Declared groups: lists of at least two known person ids, nobody in two groups."""
    ids = {p.id for p in people}
    seen: dict[int, int] = {}
    groups = []
    for g, raw in enumerate(_list(value, "conversations")):
        name = f"conversations[{g}]"
        if not isinstance(raw, list) or len(raw) < 2:
            raise _fail(name, "a list of at least two person ids", raw)
        for member in raw:
            pid = _integer(member, f"{name}", 0)
            if pid not in ids:
                raise ScenarioError(f"{name}: person {pid} is not in people")
            if pid in seen:
                raise ScenarioError(f"{name}: person {pid} is already in conversations[{seen[pid]}]")
            seen[pid] = g
        groups.append(tuple(raw))
    return tuple(groups)


def _pose(value: Any, name: str) -> tuple[float, float, float]:
    pose = _point(value, name, (2, 3))
    if len(pose) == 3:
        check_yaw(name, "yaw", pose[2], error=ScenarioError)
    return (pose[0], pose[1], pose[2] if len(pose) == 3 else 0.0)


def _inside(grid: GridSpec, xy: tuple[float, ...], name: str) -> None:
    """Refuse a point outside the map's cells; one on its upper or right border is outside (the last cell ends
    there), which the message says, since the bounds it quotes would seem to hold it."""
    if not grid.contains(np.array([xy[:2]]))[0]:
        x0, y0, x1, y1 = grid.bounds
        on_edge = (xy[0] == x1 and y0 <= xy[1] <= y1) or (xy[1] == y1 and x0 <= xy[0] <= x1)
        note = ": the upper and right borders lie outside the map's last cells" if on_edge else ""
        raise ScenarioError(f"{name}: ({xy[0]}, {xy[1]}) is outside the map (x {x0:g}..{x1:g}, y {y0:g}..{y1:g}){note}")


# --- limits: sizes checked where they enter, before anything is allocated for them (sid.checks.Limits) ------


def _limit(field: str, count: float, limit: str, unit: str, detail: str = "") -> None:
    try:
        check_limit(field, count, limit, unit, detail)
    except LimitError as exc:
        raise ScenarioError(str(exc)) from None


def _near_map(grid: GridSpec, obstacle: Obstacle, name: str) -> None:
    """Obstacle coordinates within one map diagonal of the map (a wall crossing the map can end there); farther
    ones would make rasterising a wall unbounded, and coordinates past 2^63 cells cannot be cells at all."""
    reach = math.hypot(*grid.size_m)
    if isinstance(obstacle, SegmentObstacle):
        points = {f"{name}.points[{i}]": p for i, p in enumerate(obstacle.points)}
    elif isinstance(obstacle, CircleObstacle):
        points = {f"{name}.center": obstacle.center}
        if obstacle.radius > reach:
            raise ScenarioError(f"{name}.radius: {obstacle.radius:g} m is more than the map's diagonal ({reach:g} m)")
    else:
        points = {f"{name}.min": obstacle.min, f"{name}.max": obstacle.max}
    x0, y0, x1, y1 = grid.bounds
    for field_name, (x, y) in points.items():
        if not (x0 - reach <= x <= x1 + reach and y0 - reach <= y <= y1 + reach):
            raise ScenarioError(
                f"{field_name}: ({x:g}, {y:g}) lies farther from the map (x {x0:g}..{x1:g}, y {y0:g}..{y1:g}) than "
                f"its diagonal ({reach:g} m); obstacle points must lie within that distance"
            )


def _warn_beyond_map(grid: GridSpec, obstacles: list[Obstacle], radius: float) -> None:
    """Warn of each obstacle that holds no cell of the map (it lies outside) but comes nearer its edge than the
    robot's ``radius`` (m): the costmap holds only the map's cells, so plans pass the edge as if it were not there,
    and ``sid simulate``'s robot, whose world is every obstacle, can hit it."""
    area = box(*grid.bounds)
    for i, obstacle in enumerate(obstacles):
        gap = area.distance(shape(obstacle))
        if 0 < gap < radius and not obstacle_mask([obstacle], grid).any():
            warnings.warn(
                f"obstacles[{i}]: lies outside the map (x {grid.bounds[0]:g}..{grid.bounds[2]:g}, y "
                f"{grid.bounds[1]:g}..{grid.bounds[3]:g}) but {gap:.3g} m from its edge, nearer than the robot's "
                f"radius ({radius:g} m): the costmap holds only the map's cells, so plans pass it as if it were not "
                "there (and sid simulate's robot can hit it); extend the map or move the obstacle inside",
                InputWarning,
                stacklevel=2,
            )


def _point_count(value: Any) -> int:
    """The points an obstacle's mapping gives, counted before it is read (``Limits.obstacle_points``): a wall's
    points, 4 per box, 1 for anything else (a circle, or a mapping refused when read)."""
    if not isinstance(value, dict):
        return 1
    if value.get("type") == "segment" and isinstance(value.get("points"), list):
        return len(value["points"])
    return 4 if value.get("type") == "box" else 1


def _edge_count(obstacles: list[Obstacle], people: list[Person]) -> int:
    """What each beam of the simulated scan is tested against: a wall's straight pieces, a box's 4 sides, a circle,
    a person's body."""
    pieces = (
        len(o.points) - 1 if isinstance(o, SegmentObstacle) else 4 if isinstance(o, BoxObstacle) else 1
        for o in obstacles
    )
    return sum(pieces) + len(people)


def _check_scan(grid: GridSpec, lidar: LidarSpec, layers: CostmapParams, edges: int) -> None:
    """The simulated scan's size: beams (Limits.lidar_beams), beams x the longest range in cells
    (Limits.scan_cells), the samples the scan and the LiDAR layer's ray tracing take, and beams x ``edges``
    (Limits.scan_edges), its ray tests against obstacles and people."""
    _limit("lidar.beams", lidar.beams, "lidar_beams", "beams")
    _limit("lidar", lidar.beams * edges, "scan_edges", "ray tests", f"{lidar.beams} beams x {amount(edges)} edges = ")
    longest = max([lidar.range_max] + [layers.layer_params(n).raytrace_max_range for n in layers.named("lidar")])
    ratio = longest / grid.resolution  # infinite for a range near the largest float: refused by the limit below
    cells = math.ceil(ratio) if math.isfinite(ratio) else math.inf
    detail = f"{lidar.beams} beams x {amount(cells)} cells of range ({longest:g} m at {grid.resolution:g} m) = "
    _limit("lidar", lidar.beams * cells, "scan_cells", "beam cells", detail)


def _check_inflation(grid: GridSpec, layers: CostmapParams, where: str) -> None:
    """Each inflation radius within the map's diagonal (``costmap.layers.inflation.check_reach``), checked here so
    that the error names the file's field."""
    for name in layers.named("inflation"):
        try:
            check_reach(grid, layers.layer_params(name).inflation_radius, f"{where}.{name}.inflation_radius")
        except ValueError as exc:
            raise ScenarioError(str(exc)) from exc


def _static_map(path: Path) -> OccupancyGrid:
    """The ``static_map`` file, refused when its origin is rotated: Nav2's map_server ignores the yaw, so the map
    would lie differently in Nav2 than the file says (docs/scenario.md, "The known map")."""
    try:
        static = read_map(path)
    except MapFileError as exc:
        raise ScenarioError(f"static_map: {exc}") from exc
    if static.origin_yaw != 0:
        raise ScenarioError(
            f"static_map: {path}: origin yaw {static.origin_yaw:g} rad: a rotated map is not supported (Nav2's "
            "map_server ignores the yaw); rotate the image and set the yaw to 0"
        )
    return static


def _check_overlap(static: GridSpec, grid: GridSpec, path: Path) -> None:
    """Refuse a static map that shares no area with the scenario's grid: every cell would be unknown and its walls
    would vanish without a word (an origin in other coordinates, or the wrong file)."""
    (sx0, sy0, sx1, sy1), (gx0, gy0, gx1, gy1) = static.bounds, grid.bounds
    if sx0 >= gx1 or gx0 >= sx1 or sy0 >= gy1 or gy0 >= sy1:
        raise ScenarioError(
            f"static_map: {path}: the map (x {sx0:g}..{sx1:g}, y {sy0:g}..{sy1:g}) lies outside the scenario's map "
            f"(x {gx0:g}..{gx1:g}, y {gy0:g}..{gy1:g}): no cell in common; check the two origins"
        )


def _warn_resampled(static: GridSpec, grid: GridSpec, path: Path) -> None:
    """Say that the static map is sampled onto the scenario's grid when their cells differ: another size, or
    borders shifted by part of a cell (a wall there is drawn in both cells it overlaps)."""
    offsets = ((static.origin_x - grid.origin_x) / grid.resolution, (static.origin_y - grid.origin_y) / grid.resolution)
    shifted = any(abs(o - round(o)) > BORDER_TOLERANCE for o in offsets)
    if static.resolution != grid.resolution or shifted:
        cells = f"{static.resolution:g} m cells" + (", shifted by part of a cell," if shifted else "")
        warnings.warn(
            f"static_map: {path}: {cells} sampled onto the scenario's {grid.resolution:g} m cells (each takes the "
            "most occupied map cell it overlaps)",
            InputWarning,
            stacklevel=2,
        )


TOP_LEVEL = {
    "name",
    "map",
    "obstacles",
    "static_map",
    "people",
    "conversations",
    "robot",
    "lidar",
    "groups",
    "layers",
    "simulation",
}
"""The fields of a scenario file. ``simulation`` is ``sid simulate``'s block (``sid.experiments.simulate.world``,
which reads and checks it); a scenario ignores it once it is a mapping, so one scene file serves every command."""


def scenario_from_dict(data: Any, base_dir: Path | None = None, default_name: str = "scenario") -> Scenario:
    """A Scenario from a parsed JSON/YAML mapping; ``static_map`` is relative to ``base_dir`` (default cwd)."""
    data = _mapping(data, "scenario", TOP_LEVEL, {"robot"})
    if not isinstance(data.get("simulation", {}), dict):
        raise _fail("simulation", "a mapping (sid simulate's settings, docs/simulate.md)", data["simulation"])
    name = data.get("name", default_name)
    if not isinstance(name, str) or not name:
        raise _fail("name", "a non-empty string", name)

    static_map, static_spec = None, None
    if data.get("static_map") is not None:
        raw = data["static_map"]
        if not isinstance(raw, str) or not raw:
            raise _fail("static_map", "a path to a map_server YAML file", raw)
        static_map = Path(raw) if Path(raw).is_absolute() or base_dir is None else base_dir / raw
        static_spec = _static_map(static_map).spec
    grid = _grid(data.get("map"), static_spec)
    if static_map is not None and static_spec is not None:
        _check_overlap(static_spec, grid, static_map)
        _warn_resampled(static_spec, grid, static_map)

    obstacles_data = _list(data.get("obstacles", []), "obstacles")
    _limit("obstacles", sum(map(_point_count, obstacles_data)), "obstacle_points", "points")
    obstacles = [_obstacle(o, f"obstacles[{i}]") for i, o in enumerate(obstacles_data)]
    for i, obstacle in enumerate(obstacles):
        _near_map(grid, obstacle, f"obstacles[{i}]")
    people_data = _list(data.get("people", []), "people")
    _limit("people", len(people_data), "people", "people")
    people = [_person(p, f"people[{i}]", i) for i, p in enumerate(people_data)]
    seen: dict[int, int] = {}
    walks: dict[int, Trajectory] = {}
    for i, person in enumerate(people):
        if person.id in seen:
            raise ScenarioError(f"people[{i}].id: {person.id} is already used by people[{seen[person.id]}]")
        seen[person.id] = i
        _inside(grid, (person.x, person.y), f"people[{i}]")
        walk = _walk(people_data[i], f"people[{i}]", grid, person)
        if walk is not None:
            walks[person.id] = walk
    conversations = _conversations(data.get("conversations", []), people)

    robot_data = _mapping(data["robot"], "robot", {"start", "goal", "radius", "path", "speed"}, {"start", "goal"})
    start = _pose(robot_data["start"], "robot.start")
    _inside(grid, start, "robot.start")
    robot = RobotSpec(
        start,
        _pose(robot_data["goal"], "robot.goal"),
        _length(robot_data.get("radius", RobotSpec.radius), "robot.radius", grid),
        **_motion(robot_data, "robot", grid, (start[0], start[1]), RobotSpec.speed),
    )
    _inside(grid, robot.goal, "robot.goal")
    _warn_beyond_map(grid, obstacles, robot.radius)

    lidar_data = _mapping(data.get("lidar", {}), "lidar", {f.name for f in dataclasses.fields(LidarSpec)})
    defaults = LidarSpec()
    lidar = LidarSpec(
        _integer(lidar_data.get("beams", defaults.beams), "lidar.beams", 1),
        _number(lidar_data.get("range_max", defaults.range_max), "lidar.range_max", positive=True),
        _number(lidar_data.get("height", defaults.height), "lidar.height", minimum=0.0),
        _length(lidar_data.get("body_radius", defaults.body_radius), "lidar.body_radius", grid),
    )

    layers = layers_from_dict(data.get("layers", {}), grid, lidar=lidar, edges=_edge_count(obstacles, people))

    return Scenario(
        name=name,
        grid=grid,
        robot=robot,
        obstacles=obstacles,
        people=people,
        lidar=lidar,
        static_map=static_map,
        group_params=params_from_dict(data.get("groups", {}), "groups", GroupParams),
        layers=layers,
        walks=walks,
        conversations=conversations,
    )


_Built = TypeVar("_Built")


def load_scenario(path: str | Path) -> Scenario:
    """Read a scenario file (.json, or YAML for any other suffix); errors name the file and the field."""
    return read_scenario_file(path, scenario_from_dict)


def read_scenario_file(path: str | Path, build: Callable[[Any, Path, str], _Built]) -> _Built:
    """Parse a scenario-style file and ``build(data, base_dir, default_name)`` from it (a scenario, or a richer
    record such as a simulation); a ``ScenarioError`` names the file and the field."""
    path = Path(path)
    try:
        data = load_document(path, "scenario file")
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None
    try:
        return build(data, path.parent, path.stem)
    except ScenarioError as exc:
        raise ScenarioError(f"{path}: {exc}") from exc
