"""RealSense source: a live camera or a recording (.db3 from librealsense 2.59+, .bag from older versions).

>>> with RealSenseSource("walk.db3") as source:
...     for frame in source:
...         frame.depth  # metres, aligned to frame.color

Calibration (colour and depth intrinsics, depth-to-colour extrinsics, depth scale) is read from the device or the
recording. Depth alignment (``align=``):

- ``"sid"`` (default): our ``sid.align.Aligner`` (librealsense-style rectangle splat, colour-frame z); the frame's
  depth is registered to colour and ``frame.calibration.depth`` is None.
- ``"librealsense"``: ``rs.align(rs.stream.color)``; registered as above (it stores the depth reading, not z).
- ``"none"``: the raw depth image in the depth camera's grid with the full calibration. The cheapest option when only
  keypoints need depth: ``sid.align.depth_at_color_pixels`` looks them up sparsely.

Recordings play as fast as they are read (real-time playback off, so no frame is dropped) and stop at the end of
the file.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Literal

import numpy as np
import pyrealsense2 as rs

from sid.align import Aligner
from sid.camera import Calibration, Extrinsics
from sid.frame import Frame
from sid.realsense import RealSenseFrames, calibration_from_profile, read_frameset
from sid.sources import RECORDING_SUFFIXES, FrameReadError, SourceError

AlignMode = Literal["sid", "librealsense", "none"]
_POLL_MS = 100


class RealSenseSource:
    """Iterator of ``Frame``s from a RealSense camera (``path`` None) or a recording file.

    Live options: ``serial`` (first camera when None), ``color_size`` / ``depth_size`` (width, height) and ``fps``
    (default: the paper's 1280x720 colour, 848x480 depth, 30 fps). ``timeout_s``: how long to wait for a frameset.
    After ``max_failures`` failed reads in a row the source gives up with ``SourceError``.
    The pipeline starts in the constructor (errors surface at once) and stops at the end or on ``close()``.
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
            raise ValueError(f"realsense source: align must be 'sid', 'librealsense' or 'none', got {align!r}")
        self.path = Path(path) if path is not None else None
        self.align = align
        self.timeout_s = float(timeout_s)
        self.max_failures = int(max_failures)
        self._index = 0
        self._failures = 0
        self._pipeline: rs.pipeline | None = rs.pipeline()
        config = rs.config()
        if self.path is None:
            self._configure_camera(config, serial, color_size, depth_size, fps)
        else:
            self._configure_file(config)
        try:
            profile = self._pipeline.start(config)
        except RuntimeError as exc:
            self._pipeline = None
            what = f"recording {self.path}" if self.path else "the RealSense camera"
            raise SourceError(f"cannot start {what}: {exc}") from None
        self._playback = None
        if self.path is not None:
            self._playback = profile.get_device().as_playback()
            self._playback.set_real_time(False)
        try:
            self.calibration: Calibration = calibration_from_profile(profile)
        except RuntimeError as exc:
            self.close()
            raise SourceError(f"{self._name()}: needs a depth and a colour stream ({exc})") from None
        registered = Calibration(self.calibration.color, None, Extrinsics(), self.calibration.depth_scale)
        self._frame_calibration = self.calibration if align == "none" else registered
        self._rs_align = rs.align(rs.stream.color) if align == "librealsense" else None
        self._aligner = Aligner(self.calibration) if align == "sid" else None

    def _configure_camera(
        self, config: rs.config, serial: str | None, color_size: tuple[int, int], depth_size: tuple[int, int], fps: int
    ) -> None:
        devices = rs.context().query_devices()
        if len(devices) == 0:
            raise SourceError(
                "no RealSense camera is connected (check the USB 3 cable and that no other program holds it)"
            )
        if serial is not None:
            serials = [d.get_info(rs.camera_info.serial_number) for d in devices]
            if serial not in serials:
                raise SourceError(f"no RealSense camera with serial {serial}; connected: {', '.join(serials)}")
            config.enable_device(serial)
        config.enable_stream(rs.stream.depth, depth_size[0], depth_size[1], rs.format.z16, fps)
        config.enable_stream(rs.stream.color, color_size[0], color_size[1], rs.format.rgb8, fps)

    def _configure_file(self, config: rs.config) -> None:
        assert self.path is not None
        if self.path.suffix.lower() not in RECORDING_SUFFIXES:
            raise SourceError(f"{self.path}: not a RealSense recording (expected .db3 or .bag)")
        if not self.path.is_file():
            raise SourceError(f"recording {self.path} does not exist")
        config.enable_device_from_file(str(self.path), repeat_playback=False)

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
        if self._pipeline is None:
            raise StopIteration
        frames = self._wait()
        if frames is None:
            return self._failed(f"{self._name()}: no frames within {self.timeout_s:g} s")
        try:
            raw = read_frameset(frames, self._rs_align)
        except (ValueError, RuntimeError) as exc:
            return self._failed(f"{self._name()}: frame {self._index}: {exc}")
        self._failures = 0
        return raw

    def _wait(self) -> rs.composite_frame | None:
        """The next frameset, None after ``timeout_s``; StopIteration at the end of a recording."""
        deadline = time.monotonic() + self.timeout_s
        while True:
            # Short waits so the end of a recording is noticed at once rather than after the timeout.
            ok, frames = self._pipeline.try_wait_for_frames(_POLL_MS)
            if ok:
                return frames
            if self._playback is not None and self._playback.current_status() == rs.playback_status.stopped:
                self.close()
                raise StopIteration
            if time.monotonic() > deadline:
                return None

    def _failed(self, message: str) -> RealSenseFrames:
        self._failures += 1
        index = self._index
        self._index += 1
        if self._failures >= self.max_failures:
            self.close()
            raise SourceError(f"{message} ({self._failures} failures in a row, giving up)")
        raise FrameReadError(message, index, self.path)

    def close(self) -> None:
        """Stop the pipeline (idempotent)."""
        if self._pipeline is not None:
            pipeline, self._pipeline = self._pipeline, None
            with contextlib.suppress(RuntimeError):  # never started or already stopped
                pipeline.stop()

    def __enter__(self) -> RealSenseSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
