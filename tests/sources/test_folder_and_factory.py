"""Frame sources: folders of images, RealSense recordings, the open_source factory and error handling."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from sid.perception.camera import Calibration, Extrinsics, Intrinsics
from sid.sources import FrameReadError, SourceError, frames_or_errors, open_source, skip_unreadable
from sid.sources.folder import FolderSource
from sid.sources.synthetic import SyntheticSource
from tests.conftest import realsense

INTR = {"width": 64, "height": 48, "fx": 50.0, "fy": 50.0, "cx": 31.5, "cy": 23.5, "depth_scale_m": 0.001}


def write_pair(color_path: Path, depth_path: Path, value_mm: int, seed: int = 0) -> np.ndarray:
    rgb = np.random.default_rng(seed).integers(0, 255, (48, 64, 3), dtype=np.uint8)
    color_path.parent.mkdir(parents=True, exist_ok=True)
    depth_path.parent.mkdir(parents=True, exist_ok=True)
    assert cv2.imwrite(str(color_path), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
    depth = np.full((48, 64), value_mm, np.uint16)
    depth[:5, :5] = 0
    assert cv2.imwrite(str(depth_path), depth)
    return rgb


def test_single_frame_folder(tmp_path: Path) -> None:
    rgb = write_pair(tmp_path / "color.png", tmp_path / "depth.png", 2500)
    (tmp_path / "intrinsics.json").write_text(json.dumps(INTR))
    frames = list(open_source(str(tmp_path)))
    assert len(frames) == 1
    frame = frames[0]
    assert np.array_equal(frame.color, rgb)  # RGB, not OpenCV's BGR
    assert frame.depth.dtype == np.float32 and frame.depth[10, 10] == pytest.approx(2.5)
    assert frame.depth[0, 0] == 0 and frame.calibration.depth is None
    assert frame.calibration.color.fx == 50.0


def test_sequence_folder_pairs_by_name_in_natural_order_and_skips_bad_frames(tmp_path: Path) -> None:
    for i in (1, 2, 10):
        write_pair(tmp_path / "color" / f"frame{i}.png", tmp_path / "depth" / f"frame{i}.png", 1000 * i, seed=i)
    write_pair(tmp_path / "color" / "frame3.jpg", tmp_path / "other" / "x.png", 1)  # frame3 has no depth
    (tmp_path / "depth" / "frame4.png").write_bytes(b"garbage")  # frame4: unreadable depth, no colour
    write_pair(tmp_path / "color" / "frame5.png", tmp_path / "depth" / "frame5.png", 1)
    cv2.imwrite(str(tmp_path / "depth" / "frame5.png"), np.zeros((48, 64), np.uint8))  # 8-bit depth
    (tmp_path / "intrinsics.json").write_text(json.dumps(INTR))
    source = FolderSource(tmp_path, fps=10)
    assert [name for name, _, _ in source.pairs] == ["frame1", "frame2", "frame3", "frame4", "frame5", "frame10"]
    errors: list[FrameReadError] = []
    frames = list(skip_unreadable(source, errors.append))
    assert [f.index for f in frames] == [0, 1, 5]
    assert [f.depth[20, 20] for f in frames] == pytest.approx([1.0, 2.0, 10.0])
    assert frames[2].timestamp == pytest.approx(0.5)
    assert [e.index for e in errors] == [2, 3, 4]
    assert "no depth image frame3.png" in str(errors[0])
    assert "no colour image" in str(errors[1])
    assert "frame5.png" in str(errors[2]) and "16-bit" in str(errors[2]) and errors[2].path is not None
    # The same frames and errors in the order they come, for a caller that reports errors later (sid detect).
    ordered = list(frames_or_errors(source))
    assert [(type(item).__name__, item.index) for item in ordered] == [
        ("Frame", 0), ("Frame", 1), ("FrameReadError", 2), ("FrameReadError", 3), ("FrameReadError", 4), ("Frame", 5)
    ]  # fmt: skip
    # A plain for-loop stops at the first bad frame with the specific exception.
    with pytest.raises(FrameReadError):
        list(source)


def test_folder_errors_name_the_problem(tmp_path: Path) -> None:
    with pytest.raises(SourceError, match="does not exist"):
        FolderSource(tmp_path / "nowhere")
    write_pair(tmp_path / "color.png", tmp_path / "depth.png", 1000)
    with pytest.raises(SourceError, match="intrinsics.json"):
        FolderSource(tmp_path)
    (tmp_path / "intrinsics.json").write_text("{not json")
    with pytest.raises(SourceError, match="intrinsics.json: not valid JSON"):
        FolderSource(tmp_path)
    (tmp_path / "intrinsics.json").write_text(json.dumps({**INTR, "fx": None}))
    with pytest.raises(SourceError, match="intrinsics.json: intrinsics: fx must be a number, got null"):
        FolderSource(tmp_path)
    (tmp_path / "intrinsics.json").write_text(json.dumps({**INTR, "width": 32}))
    with pytest.raises(FrameReadError, match="color.png is 64x48, the calibration says 32x48"):
        next(iter(FolderSource(tmp_path)))
    (tmp_path / "intrinsics.json").write_text(json.dumps({**INTR, "depth_aligned_to_color": False}))
    with pytest.raises(SourceError, match="not aligned"):
        FolderSource(tmp_path)
    empty = tmp_path / "empty"
    (empty / "color").mkdir(parents=True)
    (empty / "depth").mkdir()
    (empty / "intrinsics.json").write_text(json.dumps(INTR))
    with pytest.raises(SourceError, match="no images"):
        FolderSource(empty)


def test_five_people_folder(shared) -> None:  # noqa: ANN001 - fixture from conftest
    folder = shared.path("data", "rgbd", "five_people")
    frames = list(open_source(str(folder)))
    assert len(frames) == 1
    frame = frames[0]
    assert frame.color.shape == (480, 640, 3) and frame.depth.shape == (480, 640)
    valid = frame.depth[frame.depth > 0]
    assert valid.size > 0.5 * frame.depth.size and 0.5 < np.median(valid) < 10.0
    assert frame.calibration.depth is None and frame.calibration.depth_scale == 0.001


def test_recording_through_open_source(tmp_path: Path) -> None:
    realsense()
    from sid.sources.librealsense import record_synthetic
    from sid.sources.realsense import RealSenseSource

    depth_intr = Intrinsics(64, 48, 40.0, 40.0, 31.5, 23.5)
    color_intr = Intrinsics(96, 72, 70.0, 70.0, 47.5, 35.5)
    calib = Calibration(color_intr, depth_intr, Extrinsics(np.eye(3), [0.015, 0.0, 0.0]), 0.001)
    rng = np.random.default_rng(0)
    frames = [
        (rng.integers(0, 255, (72, 96, 3), dtype=np.uint8), np.full((48, 64), 1500 + 100 * k, np.uint16))
        for k in range(4)
    ]
    path = record_synthetic(tmp_path / "walk.db3", frames, calib)
    errors: list[FrameReadError] = []
    got = list(skip_unreadable(open_source(str(path)), errors.append))
    # librealsense may miss the first frame's colour or depth when playback starts; that frame is reported.
    assert len(got) + len(errors) == 4 and len(errors) <= 1
    for frame in got:
        k = round(frame.timestamp * 30)
        assert frame.index == k and frame.calibration.depth is None
        assert np.array_equal(frame.color, frames[k][0])
        inner = frame.depth[5:-5, 10:-10]
        assert np.allclose(inner, 1.5 + 0.1 * k, atol=1e-6)
    with RealSenseSource(path, align="none") as source:
        assert len(list(skip_unreadable(source, errors.append))) >= 3
        assert list(source) == []  # finished and closed


def test_open_source_dispatch_and_errors(tmp_path: Path) -> None:
    with pytest.raises(SourceError, match="no such file"):
        open_source(str(tmp_path / "nothing"))
    with pytest.raises(SourceError, match="does not exist"):
        open_source(str(tmp_path / "missing.bag"))
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(SourceError, match="not a recording"):
        open_source(str(tmp_path / "notes.txt"))
    with pytest.raises(SourceError, match="empty spec"):
        open_source("")


def test_realsense_sources_without_pyrealsense2_say_why(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """As on a machine without libusb-1.0: pyrealsense2 loads only when a RealSense source is opened."""
    monkeypatch.setitem(sys.modules, "pyrealsense2", None)  # `import pyrealsense2` now raises ImportError
    for name in ("sid.sources.realsense", "sid.sources.librealsense"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    recording = tmp_path / "walk.db3"
    recording.write_bytes(b"")
    for spec in ("realsense", str(recording)):
        with pytest.raises(SourceError, match=r"need pyrealsense2, which cannot be loaded .*libusb-1\.0-0"):
            open_source(spec)
    with pytest.raises(SourceError, match="does not exist"):  # checked before pyrealsense2 is needed
        open_source(str(tmp_path / "missing.bag"))
    assert len(list(open_source("synthetic:S1", frames=1))) == 1  # other sources never need it


def test_synthetic_spec_is_delegated() -> None:
    source = open_source("synthetic:S1", frames=1)
    assert isinstance(source, SyntheticSource)
    assert len(list(source)) == 1


def test_live_camera_absent_gives_a_clear_error() -> None:
    rs = realsense()
    if len(rs.context().query_devices()) > 0:
        pytest.skip("a RealSense camera is connected")
    with pytest.raises(SourceError, match="no RealSense camera is connected"):
        open_source("realsense")


def test_frames_of_one_name_in_two_files_are_reported_not_dropped(tmp_path: Path) -> None:
    write_pair(tmp_path / "color" / "a.png", tmp_path / "depth" / "a.png", 1000)
    write_pair(tmp_path / "color" / "a.jpg", tmp_path / "other" / "x.png", 1000)  # a second colour image of frame a
    write_pair(tmp_path / "color" / "b.png", tmp_path / "depth" / "b.png", 2000)
    (tmp_path / "intrinsics.json").write_text(json.dumps(INTR))
    errors: list[FrameReadError] = []
    frames = list(skip_unreadable(FolderSource(tmp_path), errors.append))
    assert [f.index for f in frames] == [1]
    assert [str(e) for e in errors] == [
        f"frame 'a': 2 colour images, {tmp_path / 'color' / 'a.jpg'} and {tmp_path / 'color' / 'a.png'}; keep one"
    ]
    single = tmp_path / "single"
    write_pair(single / "color.png", single / "depth.png", 1000)
    write_pair(single / "color.jpg", single / "x" / "depth.png", 1000)
    (single / "intrinsics.json").write_text(json.dumps(INTR))
    with pytest.raises(FrameReadError, match="frame 'color': 2 colour images, .*color.png and .*color.jpg; keep one"):
        list(FolderSource(single))


def test_frame_names_that_are_not_plain_numbers_sort_and_play(tmp_path: Path) -> None:
    for name in ("2", "10", "²", "x٣", "frame1"):  # "²": str.isdigit() says yes, int() refuses it
        write_pair(tmp_path / "color" / f"{name}.png", tmp_path / "depth" / f"{name}.png", 1000)
    (tmp_path / "intrinsics.json").write_text(json.dumps(INTR))
    source = FolderSource(tmp_path)
    assert [name for name, _, _ in source.pairs] == ["2", "10", "frame1", "x٣", "²"]
    assert len(list(source)) == 5


def test_a_missing_image_is_named_with_any_file_of_its_name_that_is_not_read(tmp_path: Path) -> None:
    """Depth saved as float TIFF or .npy (metres), colour as BMP: the frame is skipped naming the file sid expected,
    in the layout's own place, and the file of that name it found but does not read, with the format it reads."""
    write_pair(tmp_path / "color" / "1.png", tmp_path / "depth" / "x.png", 1000)
    np.save(tmp_path / "depth" / "1.npy", np.ones((48, 64), np.float32))
    (tmp_path / "depth" / "x.png").unlink()
    write_pair(tmp_path / "other" / "2.png", tmp_path / "depth" / "2.png", 1000)
    assert cv2.imwrite(str(tmp_path / "color" / "2.bmp"), np.zeros((48, 64, 3), np.uint8))
    (tmp_path / "intrinsics.json").write_text(json.dumps(INTR))
    errors: list[FrameReadError] = []
    assert list(skip_unreadable(FolderSource(tmp_path), errors.append)) == []
    assert [str(e) for e in errors] == [
        f"frame '1': no depth image 1.png in {tmp_path / 'depth'} ({tmp_path / 'depth' / '1.npy'} is not read: "
        "depth images are single-channel 16-bit PNGs in depth units)",
        f"frame '2': no colour image 2.png, .jpg or .jpeg in {tmp_path / 'color'} ({tmp_path / 'color' / '2.bmp'} is "
        "not read: colour images are PNG or JPEG)",
    ]
    single = tmp_path / "single"
    write_pair(single / "color.png", single / "x" / "depth.png", 1000)
    assert cv2.imwrite(str(single / "depth.tiff"), np.ones((48, 64), np.float32))  # metres, as float
    (single / "intrinsics.json").write_text(json.dumps(INTR))
    with pytest.raises(FrameReadError) as raised:
        list(FolderSource(single))
    assert str(raised.value) == (
        f"frame 'color': no depth image depth.png in {single} ({single / 'depth.tiff'} is not read: depth images are "
        "single-channel 16-bit PNGs in depth units)"
    )


def test_a_jpeg_orientation_tag_does_not_turn_the_colour_image_away_from_its_depth(tmp_path: Path) -> None:
    """Depth is registered to the stored pixels: OpenCV turned a JPEG by its EXIF orientation (180 degrees: every
    person's keypoints looked up at the wrong depth, 'no people'; 90: a 48x64 image against the header's 64x48)."""
    from PIL import Image

    stored = np.zeros((48, 64, 3), np.uint8)
    stored[:, 32:] = 255  # left half black, right half white, as stored
    for orientation in (3, 6):
        folder = tmp_path / str(orientation)
        write_pair(folder / "x.png", folder / "depth.png", 1000)
        exif = Image.Exif()
        exif[0x0112] = orientation  # EXIF Orientation: 3 = rotate 180, 6 = rotate 90
        Image.fromarray(stored).save(folder / "color.jpg", exif=exif.tobytes(), quality=100)
        (folder / "intrinsics.json").write_text(json.dumps(INTR))
        (frame,) = list(FolderSource(folder))
        assert frame.color.shape == (48, 64, 3)
        assert frame.color[:, :30].max() < 30 and frame.color[:, 34:].min() > 225


@pytest.mark.parametrize("kind", ["grey", "rgba", "16-bit"])
def test_grey_rgba_and_16_bit_colour_images_are_read_as_8_bit_rgb(tmp_path: Path, kind: str) -> None:
    rgb = write_pair(tmp_path / "color.png", tmp_path / "depth.png", 1000)
    bgr = cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)
    stored = {
        "grey": cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY),
        "rgba": cv2.cvtColor(bgr, cv2.COLOR_BGR2BGRA),
        "16-bit": bgr.astype(np.uint16) * 257,
    }[kind]
    assert cv2.imwrite(str(tmp_path / "color.png"), stored)
    (tmp_path / "intrinsics.json").write_text(json.dumps(INTR))
    (frame,) = list(FolderSource(tmp_path))
    assert frame.color.dtype == np.uint8 and frame.color.shape == (48, 64, 3)
    expected = np.repeat(stored[..., None], 3, axis=2) if kind == "grey" else rgb
    assert np.abs(frame.color.astype(int) - expected).max() <= 1


def test_an_image_cut_short_in_the_middle_of_a_sequence_is_skipped_naming_it(tmp_path: Path) -> None:
    """A JPEG cut short decoded in part (the rest grey, only libjpeg's 'Premature end of JPEG file' on stderr) and
    its frame went on as a good one; a cut PNG failed in libpng. Each is now its frame's FrameReadError, and the
    frames around it play."""
    for k in range(1, 5):
        write_pair(tmp_path / "color" / f"{k}.png", tmp_path / "depth" / f"{k}.png", 1000 * k, seed=k)
    (tmp_path / "color" / "2.png").unlink()
    assert cv2.imwrite(str(tmp_path / "color" / "2.jpg"), np.full((48, 64, 3), 200, np.uint8))
    for path in (tmp_path / "color" / "2.jpg", tmp_path / "depth" / "3.png"):
        path.write_bytes(path.read_bytes()[:-40])  # the end of the file lost, as a copy cut short
    (tmp_path / "intrinsics.json").write_text(json.dumps(INTR))
    errors: list[FrameReadError] = []
    frames = list(skip_unreadable(FolderSource(tmp_path), errors.append))
    assert [f.index for f in frames] == [0, 3]
    assert [(e.index, str(e)) for e in errors] == [
        (1, f"colour image {tmp_path / 'color' / '2.jpg'} is cut short: it ends before the image does"),
        (2, f"depth image {tmp_path / 'depth' / '3.png'} is cut short: it ends before the image does"),
    ]


def test_depth_of_another_size_than_colour_under_a_registered_calibration_says_what_it_needs(tmp_path: Path) -> None:
    write_pair(tmp_path / "color.png", tmp_path / "x" / "depth.png", 1000)
    assert cv2.imwrite(str(tmp_path / "depth.png"), np.full((24, 32), 1000, np.uint16))  # half the colour's size
    (tmp_path / "intrinsics.json").write_text(json.dumps(INTR))  # flat: depth registered to colour
    with pytest.raises(FrameReadError) as raised:
        list(FolderSource(tmp_path))
    assert str(raised.value) == (
        f"depth image {tmp_path / 'depth.png'} is 32x24, the calibration says 64x48 (depth registered to colour has "
        "the colour image's size; depth of its own size needs the calibration's depth and depth_to_color sections)"
    )
