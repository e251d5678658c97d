"""rosbag2 recordings of realsense2_camera topics (.db3 or .mcap, a bag folder or its single file), read with rosbags.

>>> for frame in Rosbag2Source("walk_bag"):  # ros2 bag record of /camera/camera/color/... and aligned depth
...     frame.depth  # metres, registered to frame.color

What is read: the colour ``sensor_msgs/Image`` (rgb8 or bgr8), the depth aligned to colour (16UC1 in depth units,
or 32FC1 metres) and the colour ``sensor_msgs/CameraInfo`` (the intrinsics of both, since the depth is aligned).
Topics default to realsense2_camera's names (``/camera/camera/...``, its 4.54+ default namespace); when those are
absent the one Image topic whose last names are ``color/image_raw`` and the one ending in
``aligned_depth_to_color/image_raw`` are used, under any namespace, with the colour topic's ``camera_info``. Colour
and depth images are paired by header stamp.

Frames are numbered by colour image (0-based). A colour image with no depth image within ``sync_tolerance``, one
whose message is damaged, whose stamp repeats an earlier colour image's or is older than a frame already read, or
whose pixels cannot be used, raises
``FrameReadError`` and the source moves on; a file damaged further in ends it with ``SourceError``.
librealsense's own .db3 recordings (topics under ``/device_0/``) are a different layout:
``is_librealsense_recording`` tells them apart and ``sid.sources.open_source`` sends them to
``sid.sources.realsense``.
"""

from __future__ import annotations

import contextlib
import sqlite3
import warnings
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from rosbags.highlevel import AnyReader, AnyReaderError
from rosbags.interfaces import Connection
from rosbags.rosbag2 import ReaderError
from rosbags.typesys import Stores, get_typestore

from sid.checks import check_number
from sid.documents import InputWarning, decode_text, load_document, special_file
from sid.perception.camera import Intrinsics
from sid.perception.frame import Frame
from sid.sources import ROSBAG2_METADATA, FrameReadError, SourceError
from sid.sources.ros_messages import (
    Stamped,
    StampPairer,
    intrinsics_from_camera_info,
    is_rectified_topic,
    rgbd_frame,
    stamp_seconds,
)

__all__ = [
    "CAMERA_INFO",
    "COLOR_TOPIC",
    "DEPTH_TOPIC",
    "IMAGE",
    "Rosbag2Source",
    "compressed_bag_files",
    "is_librealsense_recording",
    "sqlite_problem",
]

IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
COLOR_TOPIC = "/camera/camera/color/image_raw"
DEPTH_TOPIC = "/camera/camera/aligned_depth_to_color/image_raw"
_LIBREALSENSE_PREFIX = "/device_"


def _reader(path: Path) -> AnyReader:
    """An opened rosbags reader; bags without embedded message definitions (.db3) use ROS 2 Humble's types.
    SourceError naming the file and what is wrong with it (a damaged file, a metadata.yaml that is not text)."""
    metadata = path / ROSBAG2_METADATA
    if path.is_dir() and metadata.exists():
        special = special_file(metadata)
        if special:
            raise SourceError(f"rosbag2 metadata {metadata}: {special}")
        try:
            decode_text(metadata.read_bytes(), f"rosbag2 metadata {metadata}")
        except OSError as exc:
            raise SourceError(f"cannot read rosbag2 metadata {metadata}: {exc.strerror or exc}") from None
        except ValueError as exc:  # a binary file, e.g. the storage file saved under the wrong name
            raise SourceError(str(exc)) from None
    reader = AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
    try:
        reader.open()
    except (AnyReaderError, ReaderError, OSError, ValueError) as exc:
        where = metadata if path.is_dir() else path
        raise SourceError(f"cannot read rosbag2 recording {where}: {exc}") from None
    return reader


def compressed_bag_files(folder: Path) -> set[str]:
    """The storage file names of the compressed rosbag2 recording in ``folder`` (its ``metadata.yaml`` gives a
    compression mode); an empty set for any other folder, or a metadata file that does not read (the folder's
    reader then says why)."""
    metadata = folder / ROSBAG2_METADATA
    if not metadata.is_file():
        return set()
    try:
        info = load_document(metadata, "rosbag2 metadata")["rosbag2_bagfile_information"]
        if not info.get("compression_mode"):
            return set()
        return {Path(str(name)).name for name in info.get("relative_file_paths") or ()}
    except (ValueError, TypeError, KeyError, AttributeError):
        return set()


def sqlite_problem(path: Path) -> str | None:
    """Why ``path`` is not a readable SQLite database (e.g. "database disk image is malformed" for a .db3 cut
    short), or None when its schema reads."""
    try:
        with contextlib.closing(sqlite3.connect(f"file:{path}?mode=ro", uri=True)) as database:
            database.execute("SELECT name FROM sqlite_master").fetchall()
    except sqlite3.Error as exc:
        return str(exc)
    return None


def is_librealsense_recording(path: str | Path) -> bool:
    """True when the bag at ``path`` was written by librealsense (its topics live under ``/device_N/``)."""
    reader = _reader(Path(path))
    try:
        return any(c.topic.startswith(_LIBREALSENSE_PREFIX) for c in reader.connections)
    finally:
        reader.close()


def _pick(
    connections: list[Connection], msgtype: str, wanted: str | None, default: str, ending: str, option: str
) -> Connection:
    """The connection of topic ``wanted``; else ``default``; else the only ``msgtype`` topic whose last names are
    ``ending`` (whole names: ``aligned_depth_to_color/image_raw`` does not end in ``color/image_raw``). ``option``
    names the setting that chooses the topic (e.g. ``color_topic``), for the error, which also names a topic of the
    right name but another type (image_transport's ``.../image_raw/compressed``, a CompressedImage)."""
    typed = [c for c in connections if c.msgtype == msgtype]
    if wanted is not None:
        named = [c for c in typed if c.topic == wanted]
        if not named:
            other = next((c for c in connections if c.topic == wanted), None)
            if other is not None:
                raise SourceError(f"topic {wanted!r} is a {other.msgtype} topic; sid {_reads_only(msgtype)}")
            raise SourceError(f"no {msgtype} topic {wanted!r} in the bag; it has {_topics(typed, msgtype)}")
        return named[0]
    named = [c for c in typed if c.topic == default] or [
        c for c in typed if f"/{c.topic.strip('/')}".endswith(f"/{ending}")
    ]
    if len({c.topic for c in named}) != 1:
        found = "none" if not named else "several"
        others = [c for c in connections if c.msgtype != msgtype and f"/{ending}/" in c.topic]
        if others and not named:
            described = ", ".join(sorted({f"{c.topic} is a {c.msgtype} topic" for c in others}))
            raise SourceError(
                f"none of the bag's {msgtype} topics end in {ending!r} ({_topics(typed, msgtype)}); {described}; "
                f"sid {_reads_only(msgtype)}"
            )
        raise SourceError(
            f"{found} of the bag's {msgtype} topics end in {ending!r} ({_topics(typed, msgtype)}); name the topic "
            f"with {option} (sid detect --{option.replace('_', '-')})"
        )
    return named[0]


def _reads_only(msgtype: str) -> str:
    """What sid reads instead of a topic of another type, for the error naming that topic."""
    return (
        f"reads only raw {msgtype} (record the raw topics, or republish the compressed ones as raw: docs/ros2.md, "
        "section 5)"
    )


def _topics(connections: list[Connection], msgtype: str) -> str:
    names = sorted({c.topic for c in connections})
    return ", ".join(names) if names else f"no {msgtype} topics"


def _first_camera_info(reader: AnyReader, info: Connection, rectified: bool) -> Intrinsics:
    """The intrinsics of the first usable CameraInfo on ``info`` (the calibration of the whole recording; of the
    rectified images when ``rectified``); each one before it that cannot be read or used is skipped with an
    ``InputWarning``."""
    problems = []
    for connection, time_ns, raw in reader.messages(connections=[info]):
        try:
            intrinsics = intrinsics_from_camera_info(reader.deserialize(raw, connection.msgtype), rectified)
        except (AnyReaderError, ValueError) as exc:
            problems.append(f"the message at {time_ns * 1e-9:.3f} s (bag time) {_unreadable(exc)}")
            warnings.warn(f"{connection.topic}: {problems[-1]}; skipped", InputWarning, stacklevel=2)
            continue
        return intrinsics
    if problems:
        raise SourceError(f"{info.topic}: none of its {len(problems)} message(s) can be used; {problems[0]}")
    raise SourceError(f"{info.topic} holds no message")


def _unreadable(exc: Exception) -> str:
    """Why a message cannot be used, for a sentence about it."""
    if isinstance(exc, AnyReaderError):
        return f"cannot be read (a damaged message: {exc})"
    return f"cannot be used ({exc})"


class Rosbag2Source:
    """Iterator of ``Frame``s from a rosbag2 recording of realsense2_camera topics (see the module docstring).

    path: the bag folder (with metadata.yaml) or its .db3 / .mcap file. color_topic / depth_topic / info_topic:
    override the topic names. depth_scale: metres per 16UC1 depth unit (0.001, realsense2_camera's millimetres).
    sync_tolerance: largest stamp difference (s) of a colour and depth image taken as one frame.
    """

    def __init__(
        self,
        path: str | Path,
        *,
        color_topic: str | None = None,
        depth_topic: str | None = None,
        info_topic: str | None = None,
        depth_scale: float = 0.001,
        sync_tolerance: float = 0.015,
    ) -> None:
        self.path = Path(path)
        if not self.path.exists():
            raise SourceError(f"rosbag2 recording {self.path} does not exist")
        check_number("rosbag2 source", "depth_scale", depth_scale, low=0, low_open=True, unit="metres per unit")
        self.depth_scale = float(depth_scale)
        self._pairer: StampPairer[Any] = StampPairer(sync_tolerance)
        reader = _reader(self.path)
        self._reader: AnyReader | None = reader
        connections = list(reader.connections)
        try:
            self.color = _pick(connections, IMAGE, color_topic, COLOR_TOPIC, "color/image_raw", "color_topic")
            self.depth = _pick(
                connections, IMAGE, depth_topic, DEPTH_TOPIC, "aligned_depth_to_color/image_raw", "depth_topic"
            )
            namespace = self.color.topic.rsplit("/", 1)[0]
            info = f"{namespace}/camera_info"
            self.info = _pick(connections, CAMERA_INFO, info_topic, info, info.strip("/"), "info_topic")
            self.intrinsics = _first_camera_info(reader, self.info, is_rectified_topic(self.color.topic))
        except SourceError as exc:
            self.close()
            raise SourceError(f"rosbag2 recording {self.path}: {exc}") from None
        self._messages = reader.messages(connections=[self.color, self.depth])
        self._colors = 0  # colour images seen: the next colour image's frame index
        self._ready: list[Frame | FrameReadError] = []

    def __iter__(self) -> Iterator[Frame]:
        return self

    def __next__(self) -> Frame:
        while not self._ready:
            if self._reader is None:
                raise StopIteration
            try:
                connection, time_ns, raw = next(self._messages)
            except StopIteration:
                self._ready.extend(self._unpaired(self._pairer.waiting["color"]))
                self.close()
                continue
            except Exception as exc:  # a damaged file: rosbags, sqlite and mcap raise many types (OverflowError...)
                self.close()
                raise SourceError(
                    f"rosbag2 recording {self.path} is damaged after its first {self._colors} colour image(s) "
                    f"({type(exc).__name__}: {str(exc)[:200]})"
                ) from None
            self._add(connection, time_ns, raw)
        item = self._ready.pop(0)
        if isinstance(item, FrameReadError):
            raise item
        return item

    def _add(self, connection: Connection, time_ns: int, raw: bytes) -> None:
        """Deserialize one image and queue the frames and errors it completes, in frame order. A colour message
        that cannot be read is its frame's FrameReadError; a depth one an ``InputWarning`` (its colour image is then
        reported as having no depth)."""
        assert self._reader is not None  # only called while the bag is open
        stream = "color" if connection.topic == self.color.topic else "depth"
        index = self._colors
        self._colors += stream == "color"
        try:
            msg: Any = self._reader.deserialize(raw, connection.msgtype)
            stamp = stamp_seconds(msg.header)
        except AnyReaderError as exc:  # rosbags' deserializer failed: a damaged message
            problem = f"{connection.topic}: the message at {time_ns * 1e-9:.3f} s (bag time) {_unreadable(exc)}"
            if stream == "depth":
                warnings.warn(f"{self.path}: {problem}; skipped", InputWarning, stacklevel=2)
            else:
                self._ready.append(FrameReadError(f"{self.path}: frame {index}: {problem}", index, self.path))
            return
        pair = self._pairer.add(stream, stamp, (index, msg) if stream == "color" else msg)
        dropped, self._pairer.dropped_colors = self._pairer.dropped_colors, []
        duplicates, self._pairer.duplicate_colors = self._pairer.duplicate_colors, []
        late, self._pairer.late_colors = self._pairer.late_colors, []
        self._ready.extend(
            FrameReadError(
                f"{self.path}: frame {m.item[0]}: its colour image has the stamp of an earlier one ({m.stamp:.6f} s)",
                m.item[0],
                self.path,
            )
            for m in duplicates
        )
        self._ready.extend(
            FrameReadError(
                f"{self.path}: frame {m.item[0]}: its colour image's stamp ({m.stamp:.6f} s) is older than an earlier "
                f"frame's ({self._pairer.last_color_stamp:.6f} s): the stamps go back",
                m.item[0],
                self.path,
            )
            for m in late
        )
        self._ready.extend(self._unpaired(dropped))
        if pair is None:
            return
        (index, color), depth = pair[0].item, pair[1].item
        try:
            self._ready.append(rgbd_frame(index, color, depth, self.intrinsics, self.depth_scale))
        except ValueError as exc:
            self._ready.append(FrameReadError(f"{self.path}: frame {index}: {exc}", index, self.path))

    def _unpaired(self, colors: Iterable[Stamped[Any]]) -> list[FrameReadError]:
        """One FrameReadError per colour image (``item``: (frame index, message)) that found no depth image."""
        return [
            FrameReadError(
                f"{self.path}: frame {m.item[0]}: no depth image within {self._pairer.tolerance:g} s of the colour "
                f"image at {m.stamp:.3f} s",
                m.item[0],
                self.path,
            )
            for m in colors
        ]

    def close(self) -> None:
        """Close the bag (idempotent)."""
        if self._reader is not None:
            reader, self._reader = self._reader, None
            reader.close()

    def __enter__(self) -> Rosbag2Source:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
