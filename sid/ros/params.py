"""The ``sid ros`` node's ROS parameters: names, defaults and descriptions, the record the node reads them into, and
``read_params``, which declares and reads them on the node.

The fixed parameters are the ``PARAMETERS`` table; tests check the shipped parameters YAML against it. The costmap's
layers are named as Nav2's costmap_2d names them: ``costmap.plugins`` lists layer instances, a name that is not a
plugin's gets ``costmap.NAME.plugin``, and every instance its plugin's parameters as ``costmap.NAME.FIELD``; they are
declared once the list is read. The group detector's and the trackers' parameters are their records' fields, named as
in a parameters file (``sid.scenario.params_file``): ``groups.FIELD``, ``tracking.tracker.FIELD``,
``tracking.groups.FIELD`` and ``tracking.FIELD``. Importing this module imports no ROS; ``read_params`` needs an rclpy
node.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, fields, is_dataclass, replace
from typing import TYPE_CHECKING, Any

from costmap.grid import GridSpec
from costmap.plugins import PLUGINS, SECTIONS, CostmapParams
from sid.checks import check_number, check_numbers
from sid.errors import InputError
from sid.perception.groups import GroupParams
from sid.perception.mount import CameraMount
from sid.perception.robot_pose import BASE_FRAME, MAP_FRAME
from sid.scenario.loader import layers_from_dict
from sid.scenario.params_file import ParamsFile, params_file_from_dict
from sid.sources.rosbag2 import COLOR_TOPIC, DEPTH_TOPIC
from sid.tracking.session import TrackingParams

if TYPE_CHECKING:
    from rclpy.node import Node

__all__ = [
    "DEFAULT_LAYERS",
    "DESCRIPTIONS",
    "LAYERS_PARAMETER",
    "NODE_NAME",
    "NODE_PLUGINS",
    "NodeParams",
    "PARAMETERS",
    "POSE_SOURCES",
    "rcl_reason",
    "read_params",
    "ros_name",
]

NODE_NAME = "sid_social_costmap"
POSE_SOURCES = ("auto", "tf", "odom", "none")
LAYERS_PARAMETER = "costmap.plugins"
"""The ROS parameter listing the costmap's layer instances (Nav2's ``plugins``)."""
DEFAULT_LAYERS = ("tracked_people",)
"""Only sid's layer: Nav2's own costmaps keep their static, obstacle and inflation layers."""
NODE_PLUGINS = ("social", "tracked_people", "inflation")
"""The plugins the node can feed: it reads no map and no scan, so ``static`` and ``lidar`` layers would stay empty."""


@dataclass(frozen=True)
class NodeParams:
    """Every parameter of the node (ROS name = field name with ``__`` read as ``.``; metres, radians, seconds).

    ``layers``: the costmap's layer instances, from ``costmap.plugins`` and ``costmap.NAME.*`` (see the module
    docstring), each of a plugin in ``NODE_PLUGINS``. ``groups``, ``tracking``: the group detector's and the
    trackers' parameters, from ``groups.*`` and ``tracking.*``.
    """

    color_topic: str = COLOR_TOPIC
    depth_topic: str = DEPTH_TOPIC
    camera_info_topic: str = "/camera/camera/color/camera_info"
    depth_scale: float = 0.001
    sync_tolerance: float = 0.015
    camera_height: float = CameraMount.height
    camera_tilt: float = CameraMount.tilt
    camera_x: float = CameraMount.x
    camera_y: float = CameraMount.y
    camera_yaw: float = CameraMount.yaw
    pose_source: str = "auto"
    odom_topic: str = "/odom"
    global_frame: str = MAP_FRAME
    base_frame: str = BASE_FRAME
    transform_timeout: float = 0.1
    costmap__resolution: float = 0.05
    costmap__width: float = 20.0
    costmap__height: float = 20.0
    costmap__origin_x: float = -10.0
    costmap__origin_y: float = -10.0
    layers: CostmapParams = field(default_factory=lambda: CostmapParams(plugins=DEFAULT_LAYERS))
    groups: GroupParams = field(default_factory=GroupParams)
    tracking: TrackingParams = field(default_factory=TrackingParams)
    costmap_topic: str = "/social_costmap"
    filter_info_topic: str = "/social_costmap_filter_info"
    markers_topic: str = "/social_markers"
    groups_topic: str = "/social_groups"

    def __post_init__(self) -> None:
        if self.pose_source not in POSE_SOURCES:
            raise InputError(f"pose_source must be one of {', '.join(POSE_SOURCES)}, got {self.pose_source!r}")
        check_number("parameters", "depth_scale", self.depth_scale, low=0, low_open=True, unit="metres per unit")
        check_numbers("parameters", self, ("sync_tolerance", "transform_timeout"), low=0, unit="seconds")
        self.grid  # noqa: B018 - checks the costmap geometry now, with a message naming it
        self.mount  # noqa: B018 - the same for the camera mount
        taken = {ros_name(f.name).removeprefix("costmap.") for f in fields(self) if ros_name(f.name).count(".")}
        for name in self.layers.plugins:
            plugin = self.layers.plugin(name)
            if name in taken:
                raise InputError(f"{LAYERS_PARAMETER}: costmap.{name} is a parameter already; name the layer otherwise")
            if plugin not in NODE_PLUGINS:
                raise InputError(
                    f"{LAYERS_PARAMETER}: {name} is a {plugin} layer, which the node cannot feed (it reads no map and "
                    f"no scan; Nav2's own costmaps keep those layers); the node's plugins: {', '.join(NODE_PLUGINS)}"
                )

    @property
    def grid(self) -> GridSpec:
        """The published costmap's grid in ``global_frame``."""
        try:
            return GridSpec.from_size(
                self.costmap__resolution,
                (self.costmap__origin_x, self.costmap__origin_y),
                (self.costmap__width, self.costmap__height),
            )
        except ValueError as exc:
            raise InputError(f"costmap.*: {exc}") from None

    @property
    def mount(self) -> CameraMount:
        """The camera on ``base_frame``: height, tilt, position (x, y) and heading of its optical axis."""
        return CameraMount(self.camera_height, self.camera_tilt, self.camera_x, self.camera_y, self.camera_yaw)


DESCRIPTIONS: dict[str, str] = {
    "color_topic": "colour image topic (sensor_msgs/Image, rgb8 or bgr8)",
    "depth_topic": "depth image aligned to colour (sensor_msgs/Image, 16UC1 depth units or 32FC1 metres)",
    "camera_info_topic": "colour camera_info topic (intrinsics of colour and aligned depth)",
    "depth_scale": "metres per 16UC1 depth unit (realsense2_camera: 0.001)",
    "sync_tolerance": "largest stamp difference (s) of a colour and a depth image taken as one frame",
    "camera_height": "camera optical centre above the ground (m)",
    "camera_tilt": "camera downward pitch (rad)",
    "camera_x": "camera optical centre ahead of base_frame's origin (m)",
    "camera_y": "camera optical centre left of base_frame's origin (m)",
    "camera_yaw": "heading of the camera's optical axis from base_frame's x axis (rad, counter-clockwise)",
    "pose_source": "robot pose from 'tf' (tf2_ros), 'odom' (odom_topic), 'none' (robot fixed at the global "
    "frame's origin) or 'auto' (a source frame's own pose; else tf when tf2_ros is importable, else odom; until one "
    "arrives, the robot fixed at the origin, with a warning)",
    "odom_topic": "nav_msgs/Odometry topic giving base_frame's pose in global_frame (pose_source odom)",
    "global_frame": "frame of the published costmap and markers (Nav2's global_frame)",
    "base_frame": "the robot's ground frame below the camera (REP-105 base_footprint)",
    "transform_timeout": "how long to wait for the image-time transform (s, pose_source tf)",
    "costmap__resolution": "costmap cell size (m)",
    "costmap__width": "costmap extent along global x (m)",
    "costmap__height": "costmap extent along global y (m)",
    "costmap__origin_x": "global x of the costmap's lower-left corner (m)",
    "costmap__origin_y": "global y of the costmap's lower-left corner (m)",
    "layers": "the costmap's layer instances in combination order, as Nav2's plugins: a plugin's name (social, "
    "tracked_people, inflation) or a name of your own with costmap.NAME.plugin; each instance's parameters are "
    "costmap.NAME.FIELD (docs/ros2.md)",
    "costmap_topic": "nav_msgs/OccupancyGrid KeepoutFilter mask (reliable, transient local, depth 1)",
    "filter_info_topic": "nav2_msgs/CostmapFilterInfo for the mask (published when nav2_msgs is importable)",
    "markers_topic": "visualization_msgs/MarkerArray of people and groups for RViz",
    "groups_topic": "groups as JSON on std_msgs/String (docs/ros2.md); hri_msgs adds /humans/groups/*",
}


def ros_name(field: str) -> str:
    """A NodeParams field name -> its ROS parameter name (``costmap__width`` -> ``costmap.width``; ``layers`` ->
    ``costmap.plugins``)."""
    return LAYERS_PARAMETER if field == "layers" else field.replace("__", ".")


_RECORDS = tuple(f.name for f in fields(ParamsFile))
"""The NodeParams fields that are records of their own (``groups``, ``tracking``), one parameter per field of theirs."""

PARAMETERS: tuple[tuple[str, object, str], ...] = tuple(
    (ros_name(f.name), list(DEFAULT_LAYERS) if f.name == "layers" else f.default, DESCRIPTIONS[f.name])
    for f in fields(NodeParams)
    if f.name not in _RECORDS
)
"""(ROS name, default, description) of every fixed parameter, in declaration order (``costmap.plugins`` with the
names of the default layers; the instances' own parameters, and the group detector's and the trackers', are declared
by ``read_params``)."""


def _typed(name: str, value: Any, default: object) -> Any:
    """The value of parameter ``name`` in the type of its default (a YAML ``20`` for a float parameter is 20.0).
    ValueError naming the parameter for a value of another kind (``true`` or ``'abc'`` for a number, ``5`` for a
    name)."""
    if isinstance(default, float):
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise InputError(f"{name}: expected a number, got {value!r}")
        return float(value)
    if not isinstance(value, str):
        raise InputError(f"{name}: expected a name (text), got {value!r}")
    return value


def rcl_reason(error: Exception, prefix: str) -> str:
    """An rcl error's message for a person: without ``prefix`` (rclpy's "failed to ...: ") and the C source
    locations rcl appends (``, at src/rcl/arguments.c:352``)."""
    return str(error).removeprefix(prefix).split(", at ")[0]


def _check_names(node: Node, params: NodeParams) -> None:
    """ValueError naming the parameter when a topic is not a valid ROS topic name for ``node`` (empty, a space, a
    ``//``; rcl's own reason is quoted) or a frame id is empty or starts with ``/`` (tf2 refuses such ids)."""
    from rclpy.impl.implementation_singleton import rclpy_implementation

    for f in fields(params):
        value = getattr(params, f.name)
        if f.name.endswith("_topic"):
            try:
                node.resolve_topic_name(value)
            except rclpy_implementation.RCLError as exc:
                reason = rcl_reason(exc, "failed to resolve name: ")
                raise InputError(f"{f.name}: {value!r} is not a valid topic name ({reason})") from None
        elif f.name.endswith("_frame"):
            if not value:
                raise InputError(f"{f.name}: a frame id must not be empty")
            if value.startswith("/"):
                raise InputError(f"{f.name}: tf2 frame ids do not start with '/', got {value!r}")


def _declare(node: Node, name: str, default: object, description: str) -> Any:
    """Declare the parameter ``name`` on ``node`` (any type accepted: values are checked when read) and return its
    value: the one given (``-p``, a parameters file) or ``default``."""
    from rcl_interfaces.msg import ParameterDescriptor

    descriptor = ParameterDescriptor(description=description, dynamic_typing=True)
    return node.declare_parameter(name, default, descriptor).value


_SHARED_SECTIONS = {"tracked_people": "social"}
"""Plugin -> the plugin whose ``CostmapParams`` section its layers also read: the tracked-people layer draws standing
people with the social plugin's parameters (``costmap.social.*``), listed or not."""


def _layer_parameters(node: Node, names: Sequence[str]) -> dict[str, Any]:
    """Declare and read the parameters of the layer instances ``names``, as the sections of a scenario file's
    ``layers`` block (the mapping ``sid.scenario.loader.layers_from_dict`` reads): a plugin's own name -> its section
    (``costmap.social.FIELD`` -> ``social: {FIELD: ...}``), another name -> ``{plugin: P, FIELD: ...}``; and the
    section of a plugin a listed instance's plugin also reads (``_SHARED_SECTIONS``), listed or not."""
    mapping: dict[str, Any] = {}
    shared: list[str] = []  # plugins whose sections listed instances read besides their own
    for name in dict.fromkeys(names):  # a name listed twice is refused by the loader, declared once here
        if name in PLUGINS:
            plugin: Any = name
            if name in SECTIONS:
                mapping[SECTIONS[name]] = _section_parameters(node, name, name)
        else:
            description = f"plugin of the layer instance {name}: one of {', '.join(NODE_PLUGINS)}"
            plugin = _declare(node, f"costmap.{name}.plugin", "", description)
            entry = {"plugin": plugin} if plugin != "" else {}
            if isinstance(plugin, str) and plugin in SECTIONS:
                entry |= _section_parameters(node, name, plugin)
            mapping[name] = entry
        if isinstance(plugin, str) and plugin in _SHARED_SECTIONS:
            shared.append(_SHARED_SECTIONS[plugin])
    for plugin in dict.fromkeys(shared):
        if SECTIONS[plugin] not in mapping:  # else declared as a listed instance's
            readers = ", ".join(p for p, section in _SHARED_SECTIONS.items() if section == plugin)
            mapping[SECTIONS[plugin]] = _section_parameters(node, plugin, plugin, f"the {readers} layers draw with it")
    return mapping


def _section_parameters(node: Node, name: str, plugin: str, use: str = "") -> dict[str, Any]:
    """Declare and read ``costmap.NAME.FIELD`` for each field of ``plugin``'s parameters (its defaults: its
    ``CostmapParams`` section); ``use``: what else reads them, for the descriptions."""
    record = getattr(CostmapParams(), SECTIONS[plugin])
    values = {}
    also = f"; {use}" if use else ""
    for f in fields(record):
        description = f"{f.name} of the {name} layer ({plugin} plugin{also}; docs/scenario.md, layer parameters)"
        values[f.name] = _declare(node, f"costmap.{name}.{f.name}", getattr(record, f.name), description)
    return values


_RECORD_DESCRIPTIONS = {
    "groups": "the group detector (sid.perception.groups.GroupParams; docs/groups.md)",
    "tracking": (
        "the trackers' session: what counts as a jump of the robot pose, how long a missed track is reported "
        "(sid.tracking.session.TrackingParams)"
    ),
    "tracking.tracker": "the people tracker (sid.tracking.tracker.TrackerParams; docs/tracking.md)",
    "tracking.groups": "the group tracker (sid.tracking.groups.GroupTrackerParams; docs/tracking.md)",
}


def _record_parameters(node: Node, name: str, record: Any) -> dict[str, Any]:
    """Declare and read ``NAME.FIELD`` for each field of ``record`` (a parameters dataclass, its values the defaults;
    a field that is itself one, ``NAME.FIELD.*``), as the block ``name`` of a parameters file."""
    values: dict[str, Any] = {}
    for f in fields(record):
        value = getattr(record, f.name)
        if is_dataclass(value):
            values[f.name] = _record_parameters(node, f"{name}.{f.name}", value)
        else:
            description = f"{f.name} of {_RECORD_DESCRIPTIONS[name]}"
            values[f.name] = _declare(node, f"{name}.{f.name}", value, description)
    return values


def read_params(node: Node) -> NodeParams:
    """Declare every parameter of the node on ``node`` (an ``rclpy.node.Node``), each with its description, and read
    them: the fixed ones (``PARAMETERS``), then the layer instances ``costmap.plugins`` lists, Nav2-style (see the
    module docstring), built by the scenario loader's ``layers_from_dict``, and the group detector's and the trackers'
    (``groups.*``, ``tracking.*``), checked as a parameters file's. A bad value (of the wrong type, out of range, an
    invalid topic name or frame id) raises ValueError naming the parameter."""
    values = {name: _declare(node, name, default, description) for name, default, description in PARAMETERS}
    names = values.pop(LAYERS_PARAMETER)
    fixed = {
        f.name: _typed(ros_name(f.name), values[ros_name(f.name)], f.default)
        for f in fields(NodeParams)
        if f.name != "layers" and f.name not in _RECORDS
    }
    records = params_file_from_dict(
        {name: _record_parameters(node, name, getattr(ParamsFile(), name)) for name in _RECORDS}
    )
    params = NodeParams(**fixed, groups=records.groups, tracking=records.tracking)
    _check_names(node, params)
    listed = names if isinstance(names, list) and all(isinstance(n, str) for n in names) else []
    mapping = {"plugins": names, **_layer_parameters(node, listed)}
    return replace(params, layers=layers_from_dict(mapping, params.grid, where="costmap"))
