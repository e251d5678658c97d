"""ROS 2 camera messages -> sid records: ``sensor_msgs/Image`` pixels, ``sensor_msgs/CameraInfo`` intrinsics, and the
pairing of colour and depth images by their header stamps.

Works on any object with the messages' fields: rclpy messages (``sid ros``) and rosbags' deserialized messages
(``sid.sources.rosbag2``) alike; nothing here imports ROS. Images follow realsense2_camera: colour ``rgb8`` or
``bgr8`` (``rgba8``/``bgra8``/``mono8`` are read too), depth ``16UC1`` in depth units (millimetres by default,
REP-118) or ``32FC1`` in metres; depth aligned to colour, so one CameraInfo (the colour camera's) calibrates both.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import cv2
import numpy as np

from sid.checks import check_number
from sid.errors import InputError
from sid.perception.camera import Calibration, Intrinsics, warn_distortion
from sid.perception.frame import Frame

__all__ = [
    "StampPairer",
    "Stamped",
    "T",
    "color_rgb",
    "depth_metres",
    "intrinsics_from_camera_info",
    "is_rectified_topic",
    "rgbd_frame",
    "stamp_seconds",
]

# Colour encodings -> (channels, OpenCV conversion to RGB; None: already RGB).
_COLOR = {
    "rgb8": (3, None),
    "bgr8": (3, cv2.COLOR_BGR2RGB),
    "rgba8": (4, cv2.COLOR_RGBA2RGB),
    "bgra8": (4, cv2.COLOR_BGRA2RGB),
    "mono8": (1, cv2.COLOR_GRAY2RGB),
}
# Depth encodings -> numpy dtype (little-endian; is_bigendian flips it) and whether values are already metres.
_DEPTH = {"16UC1": ("<u2", False), "mono16": ("<u2", False), "32FC1": ("<f4", True)}

T = TypeVar("T")


def stamp_seconds(header: Any) -> float:
    """A ``std_msgs/Header`` stamp in seconds."""
    return float(header.stamp.sec) + float(header.stamp.nanosec) * 1e-9


def _pixels(msg: Any, dtype: str, channels: int) -> np.ndarray:
    """The (height, width[, channels]) array of an Image message, row padding (``step``) removed."""
    height, width, step = int(msg.height), int(msg.width), int(msg.step)
    item = np.dtype(dtype)
    if getattr(msg, "is_bigendian", False):
        item = item.newbyteorder(">")
    row = width * channels * item.itemsize
    raw = np.frombuffer(msg.data, dtype=np.uint8)
    if height <= 0 or width <= 0 or step < row or raw.size < height * step:
        raise InputError(
            f"image {width}x{height} {msg.encoding}: step {step} and {raw.size} bytes of data do not hold it"
        )
    rows = raw[: height * step].reshape(height, step)[:, :row]
    array = (
        np.ascontiguousarray(rows).view(item).reshape((height, width, channels) if channels > 1 else (height, width))
    )
    return array.astype(item.newbyteorder("="), copy=False)


def color_rgb(msg: Any) -> np.ndarray:
    """A colour Image -> (H, W, 3) uint8 RGB. ValueError names an encoding that is not a colour one."""
    if msg.encoding not in _COLOR:
        raise InputError(f"colour image encoding {msg.encoding!r} is not supported; use one of {', '.join(_COLOR)}")
    channels, code = _COLOR[msg.encoding]
    pixels = _pixels(msg, "u1", channels)
    return pixels.copy() if code is None else cv2.cvtColor(pixels, code)


def depth_metres(msg: Any, depth_scale: float) -> np.ndarray:
    """A depth Image -> (H, W) float32 metres (0 = no reading). ``depth_scale``: metres per unit of 16UC1 depth."""
    if msg.encoding not in _DEPTH:
        raise InputError(
            f"depth image encoding {msg.encoding!r} is not supported; use 16UC1 (depth units) or 32FC1 (m)"
        )
    dtype, metres = _DEPTH[msg.encoding]
    values = _pixels(msg, dtype, 1).astype(np.float32)
    if metres:
        return np.where(np.isfinite(values), values, np.float32(0.0))
    return values * np.float32(depth_scale)


def is_rectified_topic(topic: str) -> bool:
    """Whether an Image topic carries rectified images by ROS's naming (image_proc's ``image_rect``,
    ``image_rect_color``; realsense2_camera's ``image_rect_raw``): its last name starts with ``image_rect``."""
    return topic.rstrip("/").rsplit("/", 1)[-1].startswith("image_rect")


def intrinsics_from_camera_info(msg: Any, rectified: bool = False) -> Intrinsics:
    """A CameraInfo -> pinhole intrinsics. ValueError when unusable.

    ``rectified``: the images are rectified (``is_rectified_topic``), so their camera is the projection ``p``
    (fx, fy, cx, cy from the 3x4 ``p``, row-major, as ROS's image_geometry projects rectified images; ``k`` when
    ``p`` is left zero) with no distortion; ``k`` and ``d`` describe the raw image (with plumb_bob k1 = -0.2, ``k``
    put people 7 % too near the optical axis). Otherwise the 3x3 ``k``, and the distortion model and coefficients
    are kept; sid treats the camera as an ideal pinhole (realsense2_camera reports zero distortion), and an
    InputWarning says so when ``d`` is not all zero. ROS pixel centres are at integer coordinates, as in sid
    (librealsense), so cx, cy carry over unchanged.
    """
    k = [float(v) for v in _info_field(msg, "k")]
    p = [float(v) for v in _info_field(msg, "p")] if rectified else []
    if len(k) != 9:
        raise InputError(f"camera_info: k must hold 9 numbers, got {len(k)}")
    if rectified and len(p) != 12:
        raise InputError(f"camera_info: p must hold 12 numbers, got {len(p)}")
    rectified = rectified and p[0] != 0.0  # a p left unset (zeros) by a driver: k is all there is
    fx, fy, cx, cy = (p[0], p[5], p[2], p[6]) if rectified else (k[0], k[4], k[2], k[5])
    try:
        intrinsics = Intrinsics(
            int(msg.width),
            int(msg.height),
            fx,
            fy,
            cx,
            cy,
            "none" if rectified else str(msg.distortion_model) or "none",
            () if rectified else tuple(float(v) for v in _info_field(msg, "d")),
        )
    except ValueError as exc:
        raise InputError(f"camera_info: {exc} ({'p' if rectified else 'k'} = {p if rectified else k})") from None
    warn_distortion(intrinsics, "camera_info")
    return intrinsics


def _info_field(msg: Any, name: str) -> Any:
    """A CameraInfo matrix by its ROS 2 name (``k``), or its ROS 1 one (``K``) in a ROS 1 bag's messages."""
    return getattr(msg, name) if hasattr(msg, name) else getattr(msg, name.upper())


def rgbd_frame(
    index: int, color: Any, depth: Any, intrinsics: Intrinsics, depth_scale: float, timestamp: float | None = None
) -> Frame:
    """A colour Image and the depth Image aligned to it -> ``Frame`` (registered depth, metres).

    ``intrinsics``: the colour camera's (``intrinsics_from_camera_info``). ``timestamp`` defaults to the colour
    image's stamp (s). ValueError when an encoding is unsupported, a size differs from the calibration's, or the two
    images name different optical frames (depth that is not registered to colour).
    """
    color_frame, depth_frame = (str(m.header.frame_id).strip("/") for m in (color, depth))
    if color_frame and depth_frame and color_frame != depth_frame:
        raise InputError(
            f"the depth image is in frame {depth_frame!r} and the colour image in {color_frame!r}: the depth is not "
            "registered to colour (record or subscribe to the registered depth, e.g. "
            "aligned_depth_to_color/image_raw or depth_registered/image_raw)"
        )
    rgb, metres = color_rgb(color), depth_metres(depth, depth_scale)
    expected = (intrinsics.height, intrinsics.width)
    for name, image in (("colour", rgb), ("depth", metres)):
        if image.shape[:2] != expected:
            raise InputError(
                f"{name} image is {image.shape[1]}x{image.shape[0]}, camera_info says "
                f"{intrinsics.width}x{intrinsics.height} (is the depth aligned to colour?)"
            )
    stamp = stamp_seconds(color.header) if timestamp is None else timestamp
    return Frame(index, rgb, metres, Calibration(intrinsics, depth_scale=depth_scale), stamp)


@dataclass
class Stamped(Generic[T]):
    """A message with its header stamp in seconds."""

    stamp: float
    item: T


class StampPairer(Generic[T]):
    """Pairs colour and depth messages whose stamps differ by at most ``tolerance`` seconds.

    Feed each message as it comes (``add("color" | "depth", stamp, item)``); a message that completes a pair
    returns it as (colour, depth). Messages of one stream older than a paired one can never pair; they are dropped.
    The caller reports the colour ones, kept by why: ``dropped_colors``, waiting colour messages that found no depth
    message before a later pair (or the queue's end); ``late_colors``, a colour message that arrives with a stamp
    older than ``last_color_stamp``, the last paired one (the stamps went back), by up to ``rewind`` seconds;
    ``duplicate_colors``, a colour message whose stamp is that of one already waiting or paired (one stamp, one
    frame). A colour message more than ``rewind`` seconds older starts the pairing over (a looped recording, a clock
    reset, or the message after one stamped in the future, which made every later one late, for good): the waiting
    messages stamped after it by more than ``rewind`` are dropped (colour ones into ``dropped_colors``), and the
    trackers downstream start over likewise (``sid.tracking.session``, ``max_time_back``).
    At most ``keep`` messages wait per stream.
    """

    def __init__(self, tolerance: float, keep: int = 30, rewind: float = 1.0) -> None:
        check_number("stamp pairing", "tolerance", tolerance, low=0, unit="seconds")
        check_number("stamp pairing", "rewind", rewind, low=0, unit="seconds")
        self.tolerance = float(tolerance)
        self.rewind = float(rewind)
        self.waiting: dict[str, deque[Stamped[T]]] = {"color": deque(maxlen=keep), "depth": deque(maxlen=keep)}
        self.dropped_colors: list[Stamped[T]] = []
        self.duplicate_colors: list[Stamped[T]] = []
        self.late_colors: list[Stamped[T]] = []
        self.last_color_stamp: float | None = None
        """The stamp (s) of the last colour message paired, None before the first pair."""

    def add(self, stream: str, stamp: float, item: T) -> tuple[Stamped[T], Stamped[T]] | None:
        if stream not in self.waiting:
            raise InputError(f"stamp pairing: stream must be 'color' or 'depth', got {stream!r}")
        last = self.last_color_stamp
        if stream == "color" and last is not None and stamp < last - self.rewind:
            self._start_over(stamp)
        if stream == "color" and (
            stamp == self.last_color_stamp or any(m.stamp == stamp for m in self.waiting["color"])
        ):
            self.duplicate_colors.append(Stamped(stamp, item))
            return None
        if stream == "color" and self.last_color_stamp is not None and stamp < self.last_color_stamp:
            self.late_colors.append(Stamped(stamp, item))  # older than a frame already given: out of order
            return None
        other = self.waiting["depth" if stream == "color" else "color"]
        match = min(other, key=lambda m: abs(m.stamp - stamp), default=None)
        new = Stamped(stamp, item)
        if match is None or abs(match.stamp - stamp) > self.tolerance:
            queue = self.waiting[stream]
            if len(queue) == queue.maxlen and stream == "color":
                self.dropped_colors.append(queue[0])
            queue.append(new)
            return None
        color, depth = (new, match) if stream == "color" else (match, new)
        self._take_pair(color, depth)
        self.last_color_stamp = color.stamp
        return color, depth

    def _start_over(self, stamp: float) -> None:
        """Forget the last pair and the waiting messages stamped more than ``rewind`` after ``stamp`` (s)."""
        for stream, queue in self.waiting.items():
            later = [m for m in queue if m.stamp > stamp + self.rewind]
            if stream == "color":
                self.dropped_colors.extend(later)
            kept = [m for m in queue if m.stamp <= stamp + self.rewind]
            queue.clear()
            queue.extend(kept)
        self.last_color_stamp = None

    def _take_pair(self, color: Stamped[T], depth: Stamped[T]) -> None:
        """Take the pair out of the queues, and every message older than its own half (older colours into
        ``dropped_colors``). The queues keep arrival order, which need not be stamp order (a driver's header stamps
        can go back): the whole queue is sifted, not only its front."""
        colors, depths = self.waiting["color"], self.waiting["depth"]
        self.dropped_colors.extend(m for m in colors if m is not color and m.stamp < color.stamp)
        kept = [m for m in colors if m is not color and m.stamp > color.stamp]
        colors.clear()
        colors.extend(kept)
        kept = [m for m in depths if m is not depth and m.stamp > depth.stamp]
        depths.clear()
        depths.extend(kept)
