"""RealSense source: a live camera or a recording (.db3 from librealsense 2.59+, .bag from older versions).

>>> with RealSenseSource("walk.db3") as source:
...     for frame in source:
...         frame.depth  # metres, aligned to frame.color

Calibration (colour and depth intrinsics, depth-to-colour extrinsics, depth scale) is read from the device or the
recording. Depth alignment (``align=``):

- ``"sid"`` (default): our ``sid.perception.align.Aligner`` (librealsense-style rectangle splat, colour-frame z); the
  frame's depth is registered to colour and ``frame.calibration.depth`` is None.
- ``"librealsense"``: ``rs.align(rs.stream.color)``; registered as above (it stores the depth reading, not z).
- ``"none"``: the raw depth image in the depth camera's grid with the full calibration. The cheapest option when only
  keypoints need depth: ``sid.perception.align.depth_at_color_pixels`` looks them up sparsely.

Recordings play as fast as they are read (real-time playback off, so no frame is dropped for a slow reader) and
stop at the end of the file. They are read from the playback device (``rs.context().load_device``) through a syncer,
not through ``rs.pipeline`` + ``rs.config.enable_device_from_file``, which drops frames at the start of a recording
even with real-time playback off (realsense-ros moved to the playback API for the same reason, its PR #2669; what
was observed: docs/parameters.md). librealsense starts playing when the first sensor starts, so the first colour or
depth image can still be missed: that first frame then comes with one stream only and is reported as a
``FrameReadError`` and skipped. Rewinding or pausing the playback around the start is not done: it can stall the
playback or jump to the end of the file. The syncer delivers the first frames one stream at a time; they are paired
by timestamp here.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Literal

import numpy as np
import pyrealsense2 as rs

from sid.errors import InputError, SidError
from sid.perception.align import Aligner
from sid.perception.camera import Calibration, Extrinsics
from sid.perception.frame import Frame
from sid.sources import RECORDING_SUFFIXES, FrameReadError, SourceError
from sid.sources.librealsense import (
    RealSenseFrames,
    calibration_from_profile,
    calibration_from_profiles,
    make_frameset,
    read_frameset,
)

__all__ = ["AlignMode", "IncompleteFrame", "RealSenseSource"]

AlignMode = Literal["sid", "librealsense", "none"]
_POLL_MS = 100


class RealSenseSource:
    """Iterator of ``Frame``s from a RealSense camera (``path`` None) or a recording file.

    Live options: ``serial`` (first camera when None), ``color_size`` / ``depth_size`` (width, height) and ``fps``
    (default: the paper's 1280x720 colour, 848x480 depth, 30 fps). ``timeout_s``: how long to wait for a frameset.
    After ``max_failures`` failed reads in a row the source gives up with ``SourceError``.
    Streaming starts in the constructor (errors surface at once) and stops at the end or on ``close()``.
    """

    def __init__(
        self,
        path: str | Path | None = None,
        *,
        align: AlignMode = "sid",
        serial: str | None = None,
        color_size: tuple[int, int] = (1280, 720),
        depth_size: tuple[int, int] = (848, 480),
        fps: int = 30,
        timeout_s: float = 5.0,
        max_failures: int = 3,
    ) -> None:
        if align not in ("sid", "librealsense", "none"):
            raise InputError(f"realsense source: align must be 'sid', 'librealsense' or 'none', got {align!r}")
        self.path = Path(path) if path is not None else None
        self.align = align
        self.timeout_s = float(timeout_s)
        self.max_failures = int(max_failures)
        self._index = 0
        self._failures = 0
        self._reader: _LiveReader | _RecordingReader | None = (
            _LiveReader(serial, color_size, depth_size, fps) if self.path is None else _RecordingReader(self.path)
        )
        self.calibration: Calibration = self._reader.calibration
        registered = Calibration(self.calibration.color, None, Extrinsics(), self.calibration.depth_scale)
        self._frame_calibration = self.calibration if align == "none" else registered
        self._rs_align = rs.align(rs.stream.color) if align == "librealsense" else None
        self._aligner = Aligner(self.calibration) if align == "sid" else None

    def _name(self) -> str:
        return f"recording {self.path}" if self.path else "RealSense camera"

    def __iter__(self) -> Iterator[Frame]:
        return self

    def __next__(self) -> Frame:
        raw = self.next_raw()
        scale = np.float32(self.calibration.depth_scale)
        if self._aligner is not None:
            depth = self._aligner(raw.depth.astype(np.float32) * scale)
        elif raw.aligned is not None:
            depth = raw.aligned.astype(np.float32) * scale
        else:
            depth = raw.depth.astype(np.float32) * scale
        frame = Frame(self._index, raw.color, depth, self._frame_calibration, raw.timestamp)
        self._index += 1
        return frame

    def next_raw(self) -> RealSenseFrames:
        """The next frameset as arrays (raw uint16 depth; librealsense's alignment when ``align="librealsense"``).

        Raises StopIteration at the end of a recording, FrameReadError for a frameset that cannot be used (the
        source moves on) and SourceError after ``max_failures`` failures in a row.
        """
        if self._reader is None:
            raise StopIteration
        try:
            frames = self._reader.next_frameset(self.timeout_s)
        except StopIteration:
            self.close()
            raise
        except IncompleteFrame as exc:
            return self._failed(f"{self._name()}: {exc}")
        if frames is None:
            return self._failed(f"{self._name()}: no frames within {self.timeout_s:g} s")
        try:
            raw = read_frameset(frames, self._rs_align)
        except (ValueError, RuntimeError) as exc:
            return self._failed(f"{self._name()}: frame {self._index}: {exc}")
        self._failures = 0
        return raw

    def _failed(self, message: str) -> RealSenseFrames:
        self._failures += 1
        index = self._index
        self._index += 1
        if self._failures >= self.max_failures:
            self.close()
            raise SourceError(f"{message} ({self._failures} failures in a row, giving up)")
        raise FrameReadError(message, index, self.path)

    def close(self) -> None:
        """Stop streaming (idempotent)."""
        if self._reader is not None:
            reader, self._reader = self._reader, None
            reader.close()

    def __enter__(self) -> RealSenseSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class IncompleteFrame(SidError):
    """A recorded frame whose other stream never came (reported by the source as a FrameReadError)."""


def _orphan_message(frame: rs.frame) -> str:
    stream = "depth" if frame.get_profile().stream_type() == rs.stream.depth else "colour"
    other = "colour" if stream == "depth" else "depth"
    return f"{stream} frame at {frame.get_timestamp() / 1000:.3f} s has no {other} frame in the playback; skipped"


class _LiveReader:
    """Framesets from a connected camera through ``rs.pipeline``."""

    def __init__(self, serial: str | None, color_size: tuple[int, int], depth_size: tuple[int, int], fps: int) -> None:
        devices = rs.context().query_devices()
        if len(devices) == 0:
            raise SourceError(
                "no RealSense camera is connected (check the USB 3 cable and that no other program holds it)"
            )
        config = rs.config()
        if serial is not None:
            serials = [d.get_info(rs.camera_info.serial_number) for d in devices]
            if serial not in serials:
                raise SourceError(f"no RealSense camera with serial {serial}; connected: {', '.join(serials)}")
            config.enable_device(serial)
        config.enable_stream(rs.stream.depth, depth_size[0], depth_size[1], rs.format.z16, fps)
        config.enable_stream(rs.stream.color, color_size[0], color_size[1], rs.format.rgb8, fps)
        self.pipeline = rs.pipeline()
        try:
            profile = self.pipeline.start(config)
        except RuntimeError as exc:
            raise SourceError(f"cannot start the RealSense camera: {exc}") from None
        self.calibration = calibration_from_profile(profile)

    def next_frameset(self, timeout_s: float) -> rs.composite_frame | None:
        ok, frames = self.pipeline.try_wait_for_frames(int(timeout_s * 1000))
        return frames if ok else None

    def close(self) -> None:
        with contextlib.suppress(RuntimeError):  # already stopped
            self.pipeline.stop()


class _RecordingReader:
    """Every depth + colour frameset of a recording, through the playback device (see the module docstring)."""

    def __init__(self, path: Path) -> None:
        if path.suffix.lower() not in RECORDING_SUFFIXES:
            raise SourceError(f"{path}: not a RealSense recording (expected .db3 or .bag)")
        if not path.is_file():
            raise SourceError(f"recording {path} does not exist")
        try:
            self.device = rs.context().load_device(str(path))
        except RuntimeError as exc:
            raise SourceError(f"cannot read recording {path}: {exc}") from None
        self.playback = self.device.as_playback()
        chosen: dict[rs.stream, tuple[rs.sensor, rs.video_stream_profile]] = {}
        for sensor in self.device.query_sensors():
            for profile in sensor.get_stream_profiles():
                kind = profile.stream_type()
                if kind == rs.stream.depth and profile.format() != rs.format.z16:
                    continue
                if kind in (rs.stream.depth, rs.stream.color) and kind not in chosen:
                    chosen[kind] = (sensor, profile.as_video_stream_profile())
        missing = [
            name for kind, name in ((rs.stream.depth, "depth (z16)"), (rs.stream.color, "colour")) if kind not in chosen
        ]
        if missing:
            raise SourceError(f"recording {path} has no {' and no '.join(missing)} stream")
        (depth_sensor, depth_profile), (_, color_profile) = chosen[rs.stream.depth], chosen[rs.stream.color]
        try:
            scale = depth_sensor.as_depth_sensor().get_depth_scale()
            self.calibration = calibration_from_profiles(depth_profile, color_profile, scale)
        except RuntimeError as exc:
            raise SourceError(f"recording {path}: no calibration for the depth and colour streams ({exc})") from None
        # Frames of the two streams closer in time than half a frame period belong together.
        self.pair_tolerance_ms = 500.0 / max(depth_profile.fps(), color_profile.fps(), 1)
        self.syncer = rs.syncer()
        self.sensors: list[rs.sensor] = []
        for sensor, _ in chosen.values():
            if sensor not in self.sensors:
                self.sensors.append(sensor)
        for sensor in self.sensors:
            sensor.open([p for s, p in chosen.values() if s == sensor])
        # Real-time playback off: librealsense then waits for the reader instead of dropping frames.
        self.playback.set_real_time(False)
        for sensor in self.sensors:
            sensor.start(self.syncer)
        self.single: dict[rs.stream, rs.frame] = {}
        self.pending: rs.composite_frame | None = None
        self.started = False

    def next_frameset(self, timeout_s: float) -> rs.composite_frame | None:
        """The next frameset; None after ``timeout_s`` without one; StopIteration at the end of the file."""
        if self.pending is not None:
            frames, self.pending = self.pending, None
            return frames
        deadline = time.monotonic() + timeout_s
        while True:
            ok, frames = self.syncer.try_wait_for_frames(_POLL_MS)
            if ok:
                self.started = True
                if frames.get_depth_frame() and frames.get_color_frame():
                    return frames
                paired = self._pair(frames)
                if paired is not None:
                    return paired
                continue
            timed_out = time.monotonic() > deadline
            # A playback reports "stopped" before its first frame too, so only trust it once frames have come.
            if (self.started or timed_out) and self.playback.current_status() == rs.playback_status.stopped:
                raise StopIteration
            if timed_out:
                return None

    def _pair(self, frames: rs.composite_frame) -> rs.composite_frame | None:
        """Hold single frames until the other stream's frame of the same time comes; then bundle the two.

        A held frame that never finds its partner is reported with ``IncompleteFrame``.
        """
        orphan = None
        for frame in frames:
            kind = frame.get_profile().stream_type()
            if kind not in (rs.stream.depth, rs.stream.color):
                continue
            frame.keep()
            orphan = orphan or self.single.get(kind)
            self.single[kind] = frame
        depth, color = self.single.get(rs.stream.depth), self.single.get(rs.stream.color)
        if depth is not None and color is not None:
            if abs(depth.get_timestamp() - color.get_timestamp()) <= self.pair_tolerance_ms:
                self.single.clear()
                if orphan is not None:
                    self.pending = make_frameset([depth, color])
                    raise IncompleteFrame(_orphan_message(orphan))
                return make_frameset([depth, color])
            older = rs.stream.depth if depth.get_timestamp() < color.get_timestamp() else rs.stream.color
            orphan = orphan or self.single.pop(older)
        if orphan is not None:
            raise IncompleteFrame(_orphan_message(orphan))
        return None

    def close(self) -> None:
        for sensor in self.sensors:
            with contextlib.suppress(RuntimeError):
                sensor.stop()
            with contextlib.suppress(RuntimeError):
                sensor.close()
