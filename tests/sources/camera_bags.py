"""realsense2_camera-style rosbag2 recordings for tests, written with rosbags: colour and aligned depth images plus
the colour camera_info, under realsense2_camera's default topic names."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import cv2
import numpy as np
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from sid.perception.camera import Intrinsics

NAMESPACE = "/camera/camera"
COLOR = f"{NAMESPACE}/color/image_raw"
DEPTH = f"{NAMESPACE}/aligned_depth_to_color/image_raw"
INFO = f"{NAMESPACE}/color/camera_info"
TYPES = get_typestore(Stores.ROS2_HUMBLE)
ROS1_TYPES = get_typestore(Stores.ROS1_NOETIC)


def header(stamp_s: float, frame_id: str = "camera_color_optical_frame"):
    sec, nanosec = divmod(round(stamp_s * 1e9), 1_000_000_000)
    t = TYPES.types
    return t["std_msgs/msg/Header"](stamp=t["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec), frame_id=frame_id)


def image(stamp_s: float, pixels: np.ndarray, encoding: str):
    """A sensor_msgs/Image of ``pixels`` (uint8 H x W x C, or uint16 H x W), rows unpadded."""
    pixels = np.ascontiguousarray(pixels)
    height, width = pixels.shape[:2]
    return TYPES.types["sensor_msgs/msg/Image"](
        header=header(stamp_s),
        height=height,
        width=width,
        encoding=encoding,
        is_bigendian=0,
        step=pixels.strides[0],
        data=pixels.view(np.uint8).ravel(),
    )


def camera_info_fields(intr: Intrinsics, types, ros1: bool = False) -> dict:
    """The fields of a sensor_msgs/CameraInfo of ``intr`` (no distortion) but its header, in ``types``' spelling
    (ROS 1 names its matrices K, D, R, P)."""
    matrices = {
        "k": np.array([intr.fx, 0, intr.cx, 0, intr.fy, intr.cy, 0, 0, 1], dtype=np.float64),
        "p": np.array([intr.fx, 0, intr.cx, 0, 0, intr.fy, intr.cy, 0, 0, 0, 1, 0], dtype=np.float64),
        "r": np.eye(3).ravel(),
        "d": np.zeros(5),
    }
    roi = types.types["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
    spelt = {name.upper() if ros1 else name: matrix for name, matrix in matrices.items()}
    return {"height": intr.height, "width": intr.width, "distortion_model": "plumb_bob", "binning_x": 0,
            "binning_y": 0, "roi": roi} | spelt  # fmt: skip


def camera_info(stamp_s: float, intr: Intrinsics):
    return TYPES.types["sensor_msgs/msg/CameraInfo"](header=header(stamp_s), **camera_info_fields(intr, TYPES))


Message = tuple[str, str, int, bytes]
"""One recorded message: topic, message type, bag time (ns) and its CDR bytes."""


def camera_messages(
    frames: Iterable[tuple[np.ndarray, np.ndarray]],
    intr: Intrinsics,
    *,
    namespace: str = NAMESPACE,
    encoding: str = "rgb8",
    fps: float = 30.0,
    skip_depth: Iterable[int] = (),
    stamps: Iterable[float] | None = None,
) -> list[Message]:
    """The camera_info, colour and aligned depth messages of (RGB uint8, depth uint16 mm) frames under
    realsense2_camera's topic names in ``namespace``. encoding: the colour encoding (rgb8 or bgr8). skip_depth:
    frame numbers recorded without their depth image. stamps: each frame's header stamp (s; default 100 s +
    number / fps)."""
    skipped = set(skip_depth)
    frames = list(frames)
    times = list(stamps) if stamps is not None else [100.0 + number / fps for number in range(len(frames))]
    out: list[Message] = []
    for number, ((rgb, depth), stamp) in enumerate(zip(frames, times, strict=True)):
        time_ns = round((100.0 + number / fps) * 1e9)
        pixels = cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR) if encoding == "bgr8" else rgb
        info = TYPES.serialize_cdr(camera_info(stamp, intr), "sensor_msgs/msg/CameraInfo")
        out.append((f"{namespace}/color/camera_info", "sensor_msgs/msg/CameraInfo", time_ns, info))
        color = TYPES.serialize_cdr(image(stamp, pixels, encoding), "sensor_msgs/msg/Image")
        out.append((f"{namespace}/color/image_raw", "sensor_msgs/msg/Image", time_ns, color))
        if number not in skipped:
            aligned = TYPES.serialize_cdr(image(stamp + 0.002, depth, "16UC1"), "sensor_msgs/msg/Image")
            out.append((f"{namespace}/aligned_depth_to_color/image_raw", "sensor_msgs/msg/Image", time_ns, aligned))
    return out


def write_messages(path: Path, messages: Iterable[Message], *, mcap: bool = True, compressed: bool = False) -> Path:
    """A rosbag2 folder ``path`` of ``messages`` written by rosbags, one connection per topic, each message
    zstd-compressed when ``compressed`` (``ros2 bag record --compression-mode message``); returns the folder."""
    plugin = StoragePlugin.MCAP if mcap else StoragePlugin.SQLITE3
    connections = {}
    writer = Writer(path, version=8, storage_plugin=plugin)
    if compressed:
        writer.set_compression(CompressionMode.MESSAGE, CompressionFormat.ZSTD)
    with writer:
        for topic, msgtype, time_ns, raw in messages:
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=TYPES)
            writer.write(connections[topic], time_ns, raw)
    return path


def write_camera_bag(
    path: Path,
    frames: Iterable[tuple[np.ndarray, np.ndarray]],
    intr: Intrinsics,
    *,
    mcap: bool = True,
    encoding: str = "rgb8",
    fps: float = 30.0,
    skip_depth: Iterable[int] = (),
) -> Path:
    """Write (RGB uint8, depth uint16 mm) frames to a rosbag2 folder ``path`` (``camera_messages``); returns it."""
    messages = camera_messages(frames, intr, encoding=encoding, fps=fps, skip_depth=skip_depth)
    return write_messages(path, messages, mcap=mcap)


def write_ros1_camera_bag(path: Path, frames: Iterable[tuple[np.ndarray, np.ndarray]], intr: Intrinsics) -> Path:
    """A ROS 1 bag ``path`` (``rosbag record`` on Noetic) of realsense2_camera's ROS 1 topics: the colour camera_info,
    colour and aligned depth images of (RGB uint8, depth uint16 mm) frames at 30 Hz from 100 s; returns it."""
    t = ROS1_TYPES.types

    def ros1_header(stamp_s: float):
        sec, nanosec = divmod(round(stamp_s * 1e9), 1_000_000_000)
        stamp = t["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
        return t["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id="camera_color_optical_frame")

    def ros1_image(stamp_s: float, pixels: np.ndarray, encoding: str):
        pixels = np.ascontiguousarray(pixels)
        return t["sensor_msgs/msg/Image"](
            header=ros1_header(stamp_s),
            height=pixels.shape[0],
            width=pixels.shape[1],
            encoding=encoding,
            is_bigendian=0,
            step=pixels.strides[0],
            data=pixels.view(np.uint8).ravel(),
        )

    connections = {}
    with Ros1Writer(path) as writer:
        for number, (rgb, depth) in enumerate(frames):
            stamp = 100.0 + number / 30
            fields = camera_info_fields(intr, ROS1_TYPES, ros1=True)
            info = t["sensor_msgs/msg/CameraInfo"](header=ros1_header(stamp), **fields)
            for topic, message in (
                ("/camera/color/camera_info", info),
                ("/camera/color/image_raw", ros1_image(stamp, rgb, "rgb8")),
                ("/camera/aligned_depth_to_color/image_raw", ros1_image(stamp + 0.002, depth, "16UC1")),
            ):
                msgtype = message.__msgtype__
                if topic not in connections:
                    connections[topic] = writer.add_connection(topic, msgtype, typestore=ROS1_TYPES)
                writer.write(connections[topic], round(stamp * 1e9), ROS1_TYPES.serialize_ros1(message, msgtype))
    return path
