"""The ``sid ros`` node's ROS parameters: names, defaults and descriptions, and the record the node reads them into.

Nothing here imports ROS: the node declares each ``PARAMETERS`` entry with its description, and tests check the
shipped parameters YAML against the same table.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from costmap.grid import GridSpec
from sid.checks import check_number, check_numbers
from sid.perception.mount import CameraMount
from sid.perception.robot_pose import BASE_FRAME, MAP_FRAME
from sid.sources.rosbag2 import COLOR_TOPIC, DEPTH_TOPIC

__all__ = ["DESCRIPTIONS", "NODE_NAME", "NodeParams", "PARAMETERS", "POSE_SOURCES", "ros_name"]

NODE_NAME = "sid_social_costmap"
POSE_SOURCES = ("auto", "tf", "odom", "none")


@dataclass(frozen=True)
class NodeParams:
    """Every parameter of the node (ROS name = field name with ``__`` read as ``.``; metres, radians, seconds)."""

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
    costmap_topic: str = "/social_costmap"
    filter_info_topic: str = "/social_costmap_filter_info"
    markers_topic: str = "/social_markers"
    groups_topic: str = "/social_groups"

    def __post_init__(self) -> None:
        if self.pose_source not in POSE_SOURCES:
            raise ValueError(f"pose_source must be one of {', '.join(POSE_SOURCES)}, got {self.pose_source!r}")
        check_number("parameters", "depth_scale", self.depth_scale, low=0, low_open=True, unit="metres per unit")
        check_numbers("parameters", self, ("sync_tolerance", "transform_timeout"), low=0, unit="seconds")
        self.grid  # noqa: B018 - checks the costmap geometry now, with a message naming it
        self.mount  # noqa: B018 - the same for the camera mount

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
            raise ValueError(f"costmap.*: {exc}") from None

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
    "costmap_topic": "nav_msgs/OccupancyGrid KeepoutFilter mask (reliable, transient local, depth 1)",
    "filter_info_topic": "nav2_msgs/CostmapFilterInfo for the mask (published when nav2_msgs is importable)",
    "markers_topic": "visualization_msgs/MarkerArray of people and groups for RViz",
    "groups_topic": "groups as JSON on std_msgs/String (docs/ros2.md); hri_msgs adds /humans/groups/*",
}


def ros_name(field: str) -> str:
    """A NodeParams field name -> its ROS parameter name (``costmap__width`` -> ``costmap.width``)."""
    return field.replace("__", ".")


PARAMETERS: tuple[tuple[str, object, str], ...] = tuple(
    (ros_name(f.name), f.default, DESCRIPTIONS[f.name]) for f in fields(NodeParams)
)
"""(ROS name, default, description) of every parameter, in declaration order."""
