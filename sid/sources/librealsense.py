"""pyrealsense2 glue: calibration records to and from librealsense, synthetic recordings, frameset reading.

- ``rs_intrinsics`` / ``rs_extrinsics``: our records -> librealsense structs (``Intrinsics.from_rs`` and
  ``Extrinsics.from_rs`` in ``sid.perception.camera`` go the other way).
- ``calibration_from_profile``: the colour/depth intrinsics, depth-to-colour extrinsics and depth scale of a started
  pipeline (live camera or recording).
- ``record_synthetic``: writes colour + depth frames with a given calibration to a recording through a
  ``software_device`` and a ``recorder`` (librealsense 2.59 writes ROS 2 ``.db3``; older versions wrote ROS 1
  ``.bag``). This is what lets tests replay "camera" data through ``rs.pipeline`` and ``rs.align`` with no camera.
- ``read_frameset``: a pipeline frameset -> numpy arrays (RGB colour, raw uint16 depth, optional librealsense
  alignment).
"""

from __future__ import annotations

import gc
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pyrealsense2 as rs

from sid.errors import InputError
from sid.perception.camera import Calibration, Extrinsics, Intrinsics

__all__ = [
    "RealSenseFrames",
    "calibration_from_profile",
    "calibration_from_profiles",
    "make_frameset",
    "read_frameset",
    "record_synthetic",
    "rs_extrinsics",
    "rs_intrinsics",
]

_DISTORTIONS = {
    "none": rs.distortion.none,
    "brown_conrady": rs.distortion.brown_conrady,
    "modified_brown_conrady": rs.distortion.modified_brown_conrady,
    "inverse_brown_conrady": rs.distortion.inverse_brown_conrady,
}

# Colour formats a RealSense colour stream may carry -> conversion to RGB (None = already RGB).
_TO_RGB = {
    rs.format.rgb8: None,
    rs.format.bgr8: cv2.COLOR_BGR2RGB,
    rs.format.rgba8: cv2.COLOR_RGBA2RGB,
    rs.format.bgra8: cv2.COLOR_BGRA2RGB,
    rs.format.yuyv: cv2.COLOR_YUV2RGB_YUYV,
}


def rs_intrinsics(intr: Intrinsics) -> rs.intrinsics:
    """Our intrinsics -> ``pyrealsense2.intrinsics`` (principal point ppx/ppy = cx/cy, same pixel convention)."""
    if intr.model not in _DISTORTIONS:
        raise InputError(f"intrinsics: distortion model {intr.model!r} has no librealsense equivalent")
    out = rs.intrinsics()
    out.width, out.height = intr.width, intr.height
    out.fx, out.fy, out.ppx, out.ppy = intr.fx, intr.fy, intr.cx, intr.cy
    out.model = _DISTORTIONS[intr.model]
    out.coeffs = list(intr.coeffs)
    return out


def rs_extrinsics(ext: Extrinsics) -> rs.extrinsics:
    """Our extrinsics -> ``pyrealsense2.extrinsics`` (librealsense stores the rotation column-major)."""
    out = rs.extrinsics()
    out.rotation = [float(x) for x in ext.rotation.T.ravel()]
    out.translation = [float(x) for x in ext.translation]
    return out


def calibration_from_profiles(
    depth: rs.video_stream_profile, color: rs.video_stream_profile, depth_scale: float
) -> Calibration:
    """Calibration from the depth and colour stream profiles of a device or recording (depth_scale: m per unit)."""
    return Calibration(
        Intrinsics.from_rs(color.get_intrinsics()),
        Intrinsics.from_rs(depth.get_intrinsics()),
        Extrinsics.from_rs(depth.get_extrinsics_to(color)),
        float(depth_scale),
    )


def calibration_from_profile(profile: rs.pipeline_profile) -> Calibration:
    """Calibration of a started pipeline: colour and depth intrinsics, depth-to-colour extrinsics, depth scale."""
    return calibration_from_profiles(
        profile.get_stream(rs.stream.depth).as_video_stream_profile(),
        profile.get_stream(rs.stream.color).as_video_stream_profile(),
        profile.get_device().first_depth_sensor().get_depth_scale(),
    )


def make_frameset(frames: list[rs.frame]) -> rs.composite_frame:
    """Bundle single frames into one frameset (what ``rs.align`` takes), through a librealsense processing block."""

    def bundle(first: rs.frame, source: rs.frame_source) -> None:
        source.frame_ready(source.allocate_composite_frame(frames))

    block = rs.processing_block(bundle)
    queue = rs.frame_queue(1, keep_frames=True)
    block.start(queue)
    block.invoke(frames[0])
    ok, frameset = queue.try_wait_for_frame(1000)
    if not ok:
        raise RuntimeError("librealsense did not bundle the frames into a frameset")
    return frameset.as_frameset()


@dataclass
class RealSenseFrames:
    """One frameset as arrays. color: (H_c, W_c, 3) RGB uint8. depth: (H_d, W_d) uint16 depth units.
    aligned: librealsense's depth aligned to colour, (H_c, W_c) uint16, or None. timestamp: seconds."""

    color: np.ndarray
    depth: np.ndarray
    aligned: np.ndarray | None
    timestamp: float
    frame_number: int


def read_frameset(frames: rs.composite_frame, align: rs.align | None = None) -> RealSenseFrames:
    """Copy the colour and depth of a frameset out of librealsense (optionally aligned by ``align`` too).

    Raises ValueError when a stream is missing or the colour format is not one of rgb8/bgr8/rgba8/bgra8/yuyv.
    """
    depth_frame, color_frame = frames.get_depth_frame(), frames.get_color_frame()
    if not depth_frame or not color_frame:
        missing = " and ".join(name for name, f in (("depth", depth_frame), ("colour", color_frame)) if not f)
        raise InputError(f"frameset {frames.get_frame_number()} has no {missing} frame")
    fmt = color_frame.get_profile().format()
    if fmt not in _TO_RGB:
        raise InputError(f"colour format {fmt} is not supported; record rgb8, bgr8, rgba8, bgra8 or yuyv")
    color = np.asanyarray(color_frame.get_data())
    code = _TO_RGB[fmt]
    color = color.copy() if code is None else cv2.cvtColor(color, code)
    depth = np.asanyarray(depth_frame.get_data()).copy()
    aligned = None
    if align is not None:
        aligned_depth = align.process(frames).get_depth_frame()
        aligned = np.asanyarray(aligned_depth.get_data()).copy()
    return RealSenseFrames(color, depth, aligned, depth_frame.get_timestamp() / 1000.0, depth_frame.get_frame_number())


def record_synthetic(
    path: str | Path, frames: Iterable[tuple[np.ndarray, np.ndarray]], calib: Calibration, fps: int = 30
) -> Path:
    """Record (colour RGB uint8 (H_c, W_c, 3), depth uint16 (H_d, W_d) in ``calib.depth_scale`` units) pairs.

    The recording holds a depth stream and an rgb8 colour stream with ``calib``'s intrinsics, the depth-to-colour
    extrinsics and the depth units, so ``rs.pipeline`` + ``rs.config.enable_device_from_file`` can play it back and
    ``rs.align`` can align it. librealsense 2.59 writes ROS 2 .db3 files and refuses other suffixes (ValueError).
    """
    if calib.depth is None:
        raise InputError("record_synthetic: the calibration needs depth intrinsics (unregistered depth)")
    path = Path(path)
    device = rs.software_device()
    depth_sensor, color_sensor = device.add_sensor("Depth"), device.add_sensor("Color")
    depth_sensor.add_read_only_option(rs.option.depth_units, float(calib.depth_scale))
    depth_profile = depth_sensor.add_video_stream(_video_stream(rs.stream.depth, 0, calib.depth, fps, rs.format.z16, 2))
    color_profile = color_sensor.add_video_stream(
        _video_stream(rs.stream.color, 1, calib.color, fps, rs.format.rgb8, 3)
    )
    depth_profile = depth_profile.as_video_stream_profile()
    color_profile = color_profile.as_video_stream_profile()
    depth_profile.register_extrinsics_to(color_profile, rs_extrinsics(calib.depth_to_color))
    try:
        recorder = rs.recorder(str(path), device)
    except RuntimeError as exc:
        raise InputError(f"cannot record to {path}: {exc}") from None
    depth_sensor.open(depth_profile)
    color_sensor.open(color_profile)
    syncer = rs.syncer()
    depth_sensor.start(syncer)
    color_sensor.start(syncer)
    buffers = []  # librealsense keeps pointers to the pixels until the frames are written
    try:
        for number, (color, depth) in enumerate(frames):
            color, depth = _checked_pair(color, depth, calib, number)
            buffers.append((color, depth))
            timestamp_ms = number * 1000.0 / fps
            for sensor, profile, pixels, bpp in (
                (depth_sensor, depth_profile, depth, 2),
                (color_sensor, color_profile, color, 3),
            ):
                frame = rs.software_video_frame()
                frame.pixels, frame.bpp, frame.stride = pixels, bpp, pixels.shape[1] * bpp
                frame.timestamp, frame.frame_number, frame.profile = timestamp_ms, number, profile
                frame.domain = rs.timestamp_domain.hardware_clock
                sensor.on_video_frame(frame)
    finally:
        for sensor in (depth_sensor, color_sensor):
            sensor.stop()
            sensor.close()
        recorder.pause()
        del recorder, syncer, depth_sensor, color_sensor, device
        gc.collect()  # the recorder finishes the file when it is destroyed
    return path


def _video_stream(kind: rs.stream, uid: int, intr: Intrinsics, fps: int, fmt: rs.format, bpp: int) -> rs.video_stream:
    stream = rs.video_stream()
    stream.type, stream.index, stream.uid = kind, 0, uid
    stream.width, stream.height, stream.fps, stream.bpp, stream.fmt = intr.width, intr.height, fps, bpp, fmt
    stream.intrinsics = rs_intrinsics(intr)
    return stream


def _checked_pair(
    color: np.ndarray, depth: np.ndarray, calib: Calibration, number: int
) -> tuple[np.ndarray, np.ndarray]:
    assert calib.depth is not None
    color, depth = np.ascontiguousarray(color), np.ascontiguousarray(depth)
    if color.shape != (calib.color.height, calib.color.width, 3) or color.dtype != np.uint8:
        raise InputError(
            f"frame {number}: colour must be uint8 ({calib.color.height}, {calib.color.width}, 3), "
            f"got {color.dtype} {color.shape}"
        )
    if depth.shape != (calib.depth.height, calib.depth.width) or depth.dtype != np.uint16:
        raise InputError(
            f"frame {number}: depth must be uint16 ({calib.depth.height}, {calib.depth.width}) in depth units, "
            f"got {depth.dtype} {depth.shape}"
        )
    return color, depth
