"""sid.sources.ros_messages: Image and CameraInfo fields -> arrays and intrinsics, and stamp pairing."""

from __future__ import annotations

from collections import deque
from types import SimpleNamespace

import numpy as np
import pytest

from sid.documents import InputWarning
from sid.sources.ros_messages import (
    StampPairer,
    color_rgb,
    depth_metres,
    intrinsics_from_camera_info,
    is_rectified_topic,
    rgbd_frame,
)


def image(
    pixels: np.ndarray,
    encoding: str,
    pad: int = 0,
    bigendian: bool = False,
    stamp: float = 1.5,
    frame_id: str = "camera_color_optical_frame",
):
    """An Image-shaped record of ``pixels`` whose rows carry ``pad`` extra bytes."""
    data = pixels.astype(pixels.dtype.newbyteorder(">" if bigendian else "<"))
    rows = data.reshape(pixels.shape[0], -1).view(np.uint8)
    padded = np.concatenate([rows, np.full((rows.shape[0], pad), 7, np.uint8)], axis=1)
    sec = int(stamp)
    header = SimpleNamespace(stamp=SimpleNamespace(sec=sec, nanosec=round((stamp - sec) * 1e9)), frame_id=frame_id)
    return SimpleNamespace(
        header=header,
        height=pixels.shape[0],
        width=pixels.shape[1],
        encoding=encoding,
        is_bigendian=int(bigendian),
        step=padded.shape[1],
        data=padded.tobytes(),
    )


def test_colour_encodings_and_row_padding() -> None:
    rgb = np.random.default_rng(0).integers(0, 255, (4, 5, 3), dtype=np.uint8)
    assert np.array_equal(color_rgb(image(rgb, "rgb8", pad=3)), rgb)
    assert np.array_equal(color_rgb(image(rgb[..., ::-1].copy(), "bgr8")), rgb)
    with pytest.raises(ValueError, match="'yuv422' is not supported"):
        color_rgb(image(rgb, "yuv422"))
    short = image(rgb, "rgb8")
    short.data = short.data[:-1]
    with pytest.raises(ValueError, match="do not hold it"):
        color_rgb(short)


def test_depth_in_units_or_metres_and_either_byte_order() -> None:
    mm = np.array([[0, 1000], [2500, 65535]], np.uint16)
    for bigendian in (False, True):
        metres = depth_metres(image(mm, "16UC1", pad=2, bigendian=bigendian), 0.001)
        assert metres.dtype == np.float32 and np.allclose(metres, [[0, 1.0], [2.5, 65.535]])
    floats = np.array([[np.nan, 1.25]], np.float32)
    assert depth_metres(image(floats, "32FC1"), 0.001).tolist() == [[0.0, 1.25]]  # NaN = no reading
    with pytest.raises(ValueError, match="use 16UC1"):
        depth_metres(image(mm.astype(np.uint8), "8UC1"), 0.001)


def test_camera_info_and_frame() -> None:
    info = SimpleNamespace(
        width=5, height=4, k=[50, 0, 2, 0, 51, 1.5, 0, 0, 1], d=[0.0] * 5, distortion_model="plumb_bob"
    )
    intr = intrinsics_from_camera_info(info)
    assert (intr.fx, intr.fy, intr.cx, intr.cy, intr.width, intr.height) == (50, 51, 2, 1.5, 5, 4)
    info.k = [0.0] * 9
    with pytest.raises(ValueError, match="camera_info: .*focal lengths"):
        intrinsics_from_camera_info(info)
    rgb, mm = np.zeros((4, 5, 3), np.uint8), np.full((4, 5), 1500, np.uint16)
    frame = rgbd_frame(3, image(rgb, "rgb8"), image(mm, "16UC1"), intr, 0.001)
    assert (frame.index, frame.timestamp, frame.calibration.depth) == (3, 1.5, None)
    assert frame.depth[0, 0] == pytest.approx(1.5)
    with pytest.raises(ValueError, match="depth image is 4x3, camera_info says 5x4"):
        rgbd_frame(0, image(rgb, "rgb8"), image(mm[:3, :4], "16UC1"), intr, 0.001)


def test_depth_in_another_optical_frame_than_colour_is_refused() -> None:
    """An OpenNI camera with registration off publishes depth of the colour image's size in its own frame: taken as
    registered, it moved people by centimetres and turned facings by up to 1 rad, without a word."""
    info = SimpleNamespace(width=5, height=4, k=[50, 0, 2, 0, 51, 1.5, 0, 0, 1], d=[0.0] * 5, distortion_model="")
    intr = intrinsics_from_camera_info(info)
    rgb, mm = np.zeros((4, 5, 3), np.uint8), np.full((4, 5), 1500, np.uint16)
    depth = image(mm, "16UC1", frame_id="camera_depth_optical_frame")
    with pytest.raises(ValueError, match="depth image is in frame 'camera_depth_optical_frame' and the colour image"):
        rgbd_frame(0, image(rgb, "rgb8"), depth, intr, 0.001)
    slashed = image(mm, "16UC1", frame_id="/camera_color_optical_frame")  # ROS 1's leading slash names the same frame
    assert rgbd_frame(0, image(rgb, "rgb8"), slashed, intr, 0.001).depth[0, 0] == pytest.approx(1.5)


def test_rectified_images_take_the_projection_matrix_not_the_raw_camera(recwarn) -> None:
    """image_rect topics are undistorted: their camera is P (image_geometry), K and D describe the raw image. With K,
    a probe's plumb_bob camera put people 7 % too near the optical axis, and a warning asked to undistort them."""
    info = SimpleNamespace(
        width=5,
        height=4,
        k=[50, 0, 2, 0, 51, 1.5, 0, 0, 1],
        p=[46, 0, 2.2, 0, 0, 47, 1.4, 0, 0, 0, 1, 0],
        d=[-0.2, 0.05, 0, 0, 0],
        distortion_model="plumb_bob",
    )
    rectified = intrinsics_from_camera_info(info, rectified=True)
    assert (rectified.fx, rectified.fy, rectified.cx, rectified.cy, rectified.coeffs) == (46, 47, 2.2, 1.4, ())
    assert not [w for w in recwarn if issubclass(w.category, InputWarning)]
    with pytest.warns(InputWarning, match="distortion coefficients"):
        assert intrinsics_from_camera_info(info).fx == 50  # raw images: K, and the warning
    info.p = [0.0] * 12  # a driver that leaves P unset: K is all there is
    with pytest.warns(InputWarning, match="distortion coefficients"):
        assert intrinsics_from_camera_info(info, rectified=True).fx == 50
    topics = {
        "/head_camera/rgb/image_rect_color": True,
        "/camera/depth/image_rect_raw": True,
        "image_rect": True,
        "/camera/camera/color/image_raw": False,
        "/camera/rect/image_raw": False,
    }
    assert {topic: is_rectified_topic(topic) for topic in topics} == topics


def test_camera_info_distortion_is_said_not_applied(recwarn) -> None:
    """Non-zero distortion in a CameraInfo was taken as an ideal pinhole without a word, as it is said for a JSON."""
    info = SimpleNamespace(
        width=5, height=4, k=[50, 0, 2, 0, 51, 1.5, 0, 0, 1], d=[0.1, -0.2, 0, 0, 0], distortion_model="plumb_bob"
    )
    with pytest.warns(InputWarning, match=r"camera_info: distortion coefficients \[0.1, -0.2, 0, 0, 0\] are not"):
        assert intrinsics_from_camera_info(info).coeffs == (0.1, -0.2, 0.0, 0.0, 0.0)
    recwarn.clear()
    info.d = [0.0] * 5
    intrinsics_from_camera_info(info)
    assert not [w for w in recwarn if issubclass(w.category, InputWarning)]


def test_pairing_by_stamp() -> None:
    pairer: StampPairer[str] = StampPairer(0.01)
    assert pairer.add("color", 1.000, "c1") is None
    assert pairer.add("color", 1.033, "c2") is None
    pair = pairer.add("depth", 1.035, "d2")  # pairs with c2; c1 can never pair now
    assert pair is not None and (pair[0].item, pair[1].item) == ("c2", "d2")
    assert [m.item for m in pairer.dropped_colors] == ["c1"]
    assert pairer.add("depth", 1.100, "d3") is None and pairer.add("color", 1.095, "c3") is not None
    with pytest.raises(ValueError, match="'color' or 'depth'"):
        pairer.add("ir", 1.0, "x")


def test_a_colour_stamp_given_twice_is_a_duplicate_not_a_second_frame() -> None:
    pairer: StampPairer[str] = StampPairer(0.01)
    assert pairer.add("color", 1.0, "c1") is None
    assert pairer.add("color", 1.0, "c1 again") is None  # waiting with the same stamp
    pair = pairer.add("depth", 1.002, "d1")
    assert pair is not None and pair[0].item == "c1"
    assert pairer.add("color", 1.0, "c1 a third time") is None  # the stamp of the colour image just paired
    assert [m.item for m in pairer.duplicate_colors] == ["c1 again", "c1 a third time"]
    assert pairer.dropped_colors == []


def test_a_colour_image_older_than_a_paired_one_is_late_not_paired() -> None:
    """A stamp going back (a recording spliced, a clock reset) gives no frame out of order: it is dropped once."""
    pairer: StampPairer[str] = StampPairer(0.015)
    for k, stamp in enumerate((100.0, 100.1)):
        assert pairer.add("color", stamp, f"c{k}") is None and pairer.add("depth", stamp, f"d{k}") is not None
    assert pairer.add("depth", 100.0, "d old") is None  # waits: it may still find a colour image
    assert pairer.add("color", 100.0, "c back in time") is None  # older than c1, paired: never a frame
    assert [m.item for m in pairer.late_colors] == ["c back in time"] and pairer.last_color_stamp == 100.1
    assert pairer.dropped_colors == [] and pairer.duplicate_colors == []  # it is late, not without depth


def test_a_colour_image_far_back_in_time_starts_the_pairing_over() -> None:
    """One pair stamped in the future (or a looped recording) made every later colour image late, for good: the ROS
    node and a bag skipped every frame after it. More than ``rewind`` (1 s) back, the pairing starts over."""
    pairer: StampPairer[str] = StampPairer(0.015)
    assert pairer.add("color", 100.0, "c0") is None and pairer.add("depth", 100.0, "d0") is not None
    assert pairer.add("color", 1e6, "future") is None and pairer.add("depth", 1e6, "future d") is not None
    assert pairer.add("color", 2e6, "waiting in the future") is None
    assert pairer.add("depth", 100.1, "d1") is None  # comes first, and waits
    pair = pairer.add("color", 100.1, "c1")
    assert pair is not None and (pair[0].item, pair[1].item) == ("c1", "d1")
    assert [m.item for m in pairer.dropped_colors] == ["waiting in the future"] and pairer.late_colors == []
    assert pairer.add("color", 99.5, "c back 0.6 s") is None  # within rewind: late, as before
    assert [m.item for m in pairer.late_colors] == ["c back 0.6 s"]


def test_colour_images_waiting_out_of_stamp_order_each_end_once() -> None:
    """Colour images arrive in bag order, which need not be stamp order: the one a depth image pairs leaves the queue
    wherever it waits (it was left waiting behind a later stamp and reported a second time as unpaired), and the older
    ones behind it are dropped once."""
    pairer: StampPairer[str] = StampPairer(0.015)
    for stamp, item in ((100.3, "c late"), (100.0, "c early"), (100.1, "c middle")):
        assert pairer.add("color", stamp, item) is None
    pair = pairer.add("depth", 100.1, "d")
    assert pair is not None and pair[0].item == "c middle"
    assert [m.item for m in pairer.waiting["color"]] == ["c late"]
    assert [m.item for m in pairer.dropped_colors] == ["c early"]
    assert pairer.waiting["depth"] == deque()
