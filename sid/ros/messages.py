"""ROS 2 messages built from ``sid.ros.convert``'s fields (needs rclpy's message packages: nav_msgs, std_msgs,
geometry_msgs, visualization_msgs). ``nav2_msgs`` and ``hri_msgs`` are optional: ``filter_info_type`` and
``ids_list_type`` return None when they are not importable."""

from __future__ import annotations

import array
from collections.abc import Sequence
from typing import Any

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, Pose, Quaternion, Vector3
from nav_msgs.msg import MapMetaData, OccupancyGrid
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

from sid.ros.convert import GridFields, MarkerFields, quaternion_from_yaw

__all__ = [
    "KEEPOUT_FILTER",
    "MARKER_TYPES",
    "filter_info",
    "filter_info_type",
    "header",
    "ids_list_type",
    "marker_array",
    "occupancy_grid",
]

MARKER_TYPES = {
    "arrow": Marker.ARROW,
    "cylinder": Marker.CYLINDER,
    "line_strip": Marker.LINE_STRIP,
    "text_view_facing": Marker.TEXT_VIEW_FACING,
}
KEEPOUT_FILTER = 0
"""``nav2_msgs/CostmapFilterInfo.type`` of a keepout mask."""


def header(frame_id: str, stamp: Time) -> Header:
    return Header(frame_id=frame_id, stamp=stamp)


def occupancy_grid(fields: GridFields, stamp: Time) -> OccupancyGrid:
    """The OccupancyGrid of ``fields`` stamped ``stamp`` (also its map_load_time)."""
    x, y, z, w = fields.origin_orientation
    origin = Pose(
        position=Point(x=fields.origin_x, y=fields.origin_y, z=0.0), orientation=Quaternion(x=x, y=y, z=z, w=w)
    )
    info = MapMetaData(
        map_load_time=stamp, resolution=fields.resolution, width=fields.width, height=fields.height, origin=origin
    )
    msg = OccupancyGrid(header=header(fields.frame_id, stamp), info=info)
    msg.data = array.array("b", fields.data.tobytes())
    return msg


def marker_array(markers: Sequence[MarkerFields], frame_id: str, stamp: Time) -> MarkerArray:
    """DELETEALL (the last frame's markers go) followed by one ADD marker per ``MarkerFields``."""
    out = [Marker(header=header(frame_id, stamp), action=Marker.DELETEALL)]
    for m in markers:
        qx, qy, qz, qw = quaternion_from_yaw(m.yaw)
        out.append(
            Marker(
                header=header(frame_id, stamp),
                ns=m.namespace,
                id=m.id,
                type=MARKER_TYPES[m.kind],
                action=Marker.ADD,
                pose=Pose(position=Point(x=m.x, y=m.y, z=m.z), orientation=Quaternion(x=qx, y=qy, z=qz, w=qw)),
                scale=Vector3(x=float(m.scale[0]), y=float(m.scale[1]), z=float(m.scale[2])),
                color=ColorRGBA(r=m.color[0], g=m.color[1], b=m.color[2], a=m.color[3]),
                points=[Point(x=px, y=py, z=0.05) for px, py in m.points],
                text=m.text,
            )
        )
    return MarkerArray(markers=out)


def filter_info_type() -> Any | None:
    """``nav2_msgs.msg.CostmapFilterInfo``, or None when nav2_msgs is not importable."""
    try:
        from nav2_msgs.msg import CostmapFilterInfo
    except ImportError:
        return None
    return CostmapFilterInfo


def filter_info(message_type: Any, mask_topic: str, frame_id: str, stamp: Time) -> Any:
    """The CostmapFilterInfo announcing a keepout mask on ``mask_topic`` (base 0, multiplier 1: costs as masked)."""
    return message_type(
        header=header(frame_id, stamp), type=KEEPOUT_FILTER, filter_mask_topic=mask_topic, base=0.0, multiplier=1.0
    )


def ids_list_type() -> Any | None:
    """``hri_msgs.msg.IdsList`` (REP-155), or None when hri_msgs is not importable."""
    try:
        from hri_msgs.msg import IdsList
    except ImportError:
        return None
    return IdsList
