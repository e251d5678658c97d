"""``nav_msgs/msg/OccupancyGrid`` messages in an MCAP file (rosbag2 storage), written and read with ``rosbags``.

The writer makes a rosbag2 bag with MCAP storage and keeps its single ``.mcap`` file: ROS 2 (Humble and later)
plays it with ``ros2 bag play -s mcap FILE.mcap``, Foxglove opens it, and ``read_occupancy_grids`` reads it back.
Topics are offered reliable + transient local (keep last 1), as map topics are, so late subscribers such as RViz
still get the grid.
"""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Literal

import numpy as np
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.rosbag2 import Reader, StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore
from rosbags.typesys.stores.ros2_humble import nav_msgs__msg__OccupancyGrid as OccupancyGridMsg

from costmap.grid import GridSpec
from costmap.occupancy import OccupancyGrid
from sid.errors import InputError, InputTypeError

__all__ = ["DISTROS", "MSGTYPE", "read_occupancy_grids", "write_occupancy_mcap"]

MSGTYPE = "nav_msgs/msg/OccupancyGrid"
DISTROS = {"humble": Stores.ROS2_HUMBLE, "jazzy": Stores.ROS2_JAZZY}
_LATCHED = Qos(
    QosHistory.KEEP_LAST,
    1,
    QosReliability.RELIABLE,
    QosDurability.TRANSIENT_LOCAL,
    QosTime(0, 0),
    QosTime(0, 0),
    QosLiveliness.AUTOMATIC,
    QosTime(0, 0),
    False,
)


def _message(typestore: Typestore, grid: OccupancyGrid, stamp_ns: int) -> object:
    t = typestore.types
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    stamp = t["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
    half = grid.origin_yaw / 2
    pose = t["geometry_msgs/msg/Pose"](
        position=t["geometry_msgs/msg/Point"](x=grid.spec.origin_x, y=grid.spec.origin_y, z=0.0),
        orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=float(np.sin(half)), w=float(np.cos(half))),
    )
    info = t["nav_msgs/msg/MapMetaData"](
        map_load_time=stamp,
        resolution=grid.spec.resolution,
        width=grid.spec.width,
        height=grid.spec.height,
        origin=pose,
    )
    header = t["std_msgs/msg/Header"](stamp=stamp, frame_id=grid.frame_id)
    return t[MSGTYPE](header=header, info=info, data=grid.data.ravel().copy())


def write_occupancy_mcap(
    path: str | Path,
    grids: Mapping[str, OccupancyGrid],
    *,
    stamp_ns: int = 0,
    distro: Literal["humble", "jazzy"] = "humble",
) -> Path:
    """Write one OccupancyGrid message per topic (e.g. {"/costmap": ..., "/social_costmap": ...}) to ``path``.

    ``path`` must end in .mcap and not exist. ``stamp_ns``: header stamp and bag time (ns since the epoch).
    """
    path = Path(path)
    if path.suffix != ".mcap":
        raise InputError(f"{path}: an MCAP file name must end in .mcap")
    if path.exists():
        raise InputError(f"{path}: already exists; the writer does not overwrite bags")
    if distro not in DISTROS:
        raise InputError(f"unknown ROS 2 distro {distro!r}; use one of {sorted(DISTROS)}")
    typestore = get_typestore(DISTROS[distro])
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=path.parent) as tmp:
        bag = Path(tmp) / path.stem
        with Writer(bag, version=8, storage_plugin=StoragePlugin.MCAP) as writer:
            for topic, grid in grids.items():
                connection = writer.add_connection(topic, MSGTYPE, typestore=typestore, offered_qos_profiles=[_LATCHED])
                raw = typestore.serialize_cdr(_message(typestore, grid, stamp_ns), MSGTYPE)
                writer.write(connection, int(stamp_ns), raw)
        shutil.move(bag / f"{path.stem}.mcap", path)
    return path


def _float32_decimal(value: float) -> float:
    """MapMetaData.resolution is float32: read back the shortest decimal it prints as (0.05, not 0.0500000007)."""
    return float(str(np.float32(value)))


def read_occupancy_grids(path: str | Path) -> dict[str, list[OccupancyGrid]]:
    """Every OccupancyGrid in a bag (an .mcap file or a rosbag2 folder), by topic, in time order."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: no such bag")
    out: dict[str, list[OccupancyGrid]] = {}
    typestore = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(path) as reader:
        connections = [c for c in reader.connections if c.msgtype == MSGTYPE]
        for connection, _, raw in reader.messages(connections=connections):
            msg = typestore.deserialize_cdr(raw, MSGTYPE)
            if not isinstance(msg, OccupancyGridMsg):  # the Humble store builds this class for MSGTYPE
                raise InputTypeError(f"{path}: {MSGTYPE} deserialized as {type(msg).__name__}")
            grids = out.setdefault(connection.topic, [])
            where = f"{path}: {connection.topic}, message {len(grids) + 1}"
            try:
                grids.append(_grid(msg))
            except ValueError as exc:
                raise InputError(f"{where}: {exc}") from exc
    return out


def _grid(msg: OccupancyGridMsg) -> OccupancyGrid:
    """The grid of one message; ValueError for a bad geometry or data not of width x height cells."""
    q = msg.info.origin.orientation
    yaw = float(2 * np.arctan2(q.z, q.w))
    info = msg.info
    spec = GridSpec(
        _float32_decimal(info.resolution), info.origin.position.x, info.origin.position.y, info.width, info.height
    )
    if len(msg.data) != spec.width * spec.height:
        raise InputError(
            f"data holds {len(msg.data)} cells, not width x height = {spec.width} x {spec.height} = "
            f"{spec.width * spec.height}"
        )
    data = np.asarray(msg.data, dtype=np.int8).reshape(spec.shape)
    return OccupancyGrid(spec, data, yaw, msg.header.frame_id)
