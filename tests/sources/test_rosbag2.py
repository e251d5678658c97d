"""rosbag2 recordings of realsense2_camera topics (sid.sources.rosbag2) and their dispatch by open_source."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from sid.cli import main
from sid.documents import InputWarning
from sid.perception.frame import Frame
from sid.perception.pipeline import Pipeline
from sid.sources import FrameReadError, SourceError, open_source, skip_unreadable
from sid.sources.rosbag2 import Rosbag2Source, is_librealsense_recording
from sid.sources.synthetic import SyntheticSource
from sid.synthetic.pose import TruthPose
from tests.conftest import realsense, shared_path
from tests.sources.camera_bags import (
    COLOR,
    INFO,
    TYPES,
    camera_messages,
    header,
    write_camera_bag,
    write_messages,
    write_ros1_camera_bag,
)


def synthetic_pairs(count: int) -> tuple[list[tuple[np.ndarray, np.ndarray]], list[Frame]]:
    """(RGB, depth mm uint16) pairs of the S3 scene (three people) with registered depth, and the frames."""
    frames = list(SyntheticSource("S3", frames=count, seed=3, registered=True))
    pairs = [(f.color, np.round(f.depth * 1000).astype(np.uint16)) for f in frames]
    return pairs, frames


def write_folder(folder: Path, pairs: list[tuple[np.ndarray, np.ndarray]], intrinsics: dict) -> Path:
    for sub in ("color", "depth"):
        (folder / sub).mkdir(parents=True)
    for number, (rgb, depth) in enumerate(pairs):
        assert cv2.imwrite(str(folder / "color" / f"{number}.png"), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
        assert cv2.imwrite(str(folder / "depth" / f"{number}.png"), depth)
    (folder / "intrinsics.json").write_text(json.dumps(intrinsics))
    return folder


@pytest.mark.parametrize(("mcap", "encoding"), [(True, "rgb8"), (False, "bgr8")])
def test_bag_gives_the_frames_and_people_of_the_same_folder(tmp_path: Path, mcap: bool, encoding: str) -> None:
    pairs, synthetic = synthetic_pairs(3)
    intr = synthetic[0].calibration.color
    bag = write_camera_bag(tmp_path / "bag", pairs, intr, mcap=mcap, encoding=encoding)
    folder = write_folder(tmp_path / "frames", pairs, intr.to_dict())
    storage = next(bag.glob("*.mcap" if mcap else "*.db3"))
    for spec in (bag, storage):  # the bag folder and its single storage file
        from_bag, from_folder = list(open_source(str(spec))), list(open_source(str(folder)))
        assert isinstance(open_source(str(spec)), Rosbag2Source)
        assert [f.index for f in from_bag] == [0, 1, 2]
        assert from_bag[1].timestamp == pytest.approx(100 + 1 / 30)
        for a, b in zip(from_bag, from_folder, strict=True):
            assert np.array_equal(a.color, b.color)
            assert np.array_equal(a.depth, b.depth)
            assert np.allclose(a.calibration.color.K, b.calibration.color.K)
            assert a.calibration.depth is None and a.calibration.depth_scale == 0.001
    # The same pose detections (the scene's truth, per frame index) give the same people from both sources.
    truth = {f.index: TruthPose()(f) for f in synthetic}
    pipeline = Pipeline(lambda frame: truth[frame.index])
    bag_people = [[(p.x, p.y, p.theta) for p in pipeline(f).people] for f in open_source(str(bag))]
    folder_people = [[(p.x, p.y, p.theta) for p in pipeline(f).people] for f in open_source(str(folder))]
    assert len(bag_people[0]) == 3 and bag_people == folder_people


@pytest.mark.parametrize("mcap", [True, False])
def test_a_compressed_bag_reads_from_its_folder_and_from_its_storage_file(tmp_path: Path, mcap: bool) -> None:
    """``ros2 bag record --compression-mode message``: given its storage file (as the docs allow), every message
    was reported "damaged" (only the folder's metadata.yaml says how they were compressed)."""
    pairs, synthetic = synthetic_pairs(2)
    intr = synthetic[0].calibration.color
    bag = write_messages(tmp_path / "bag", camera_messages(pairs, intr), mcap=mcap, compressed=True)
    storage = next(bag.glob("*.mcap" if mcap else "*.db3"))
    for spec in (bag, storage):
        frames = list(open_source(str(spec)))
        assert [f.index for f in frames] == [0, 1]
        assert all(np.array_equal(f.color, rgb) for f, (rgb, _) in zip(frames, pairs, strict=True))


def test_a_ros1_bag_of_realsense_topics_reads_as_a_rosbag2_one(tmp_path: Path) -> None:
    """A ROS 1 ``rosbag record`` went to librealsense, whose error ("file does not contain topic /file_version")
    suggested a damaged file; rosbags reads it like a rosbag2 recording (CameraInfo's K and D in ROS 1 spelling)."""
    pairs, synthetic = synthetic_pairs(2)
    intr = synthetic[0].calibration.color
    bag = write_ros1_camera_bag(tmp_path / "robot.bag", pairs, intr)
    source = open_source(str(bag))
    assert isinstance(source, Rosbag2Source) and not is_librealsense_recording(bag)
    frames = list(source)
    assert [f.index for f in frames] == [0, 1] and frames[1].timestamp == pytest.approx(100 + 1 / 30)
    assert np.allclose(frames[0].calibration.color.K, intr.K)
    assert np.array_equal(frames[1].depth, pairs[1][1] * np.float32(0.001))


def test_sid_detect_reads_a_bag_as_it_reads_the_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The real five-people frame, twice, as a realsense2_camera bag and as a folder: the same JSON lines."""
    real = shared_path("data", "rgbd", "five_people")
    model = shared_path("models", "yolo11n-pose-256.onnx")
    rgb = cv2.cvtColor(cv2.imread(str(real / "color.png")), cv2.COLOR_BGR2RGB)
    depth = cv2.imread(str(real / "depth.png"), cv2.IMREAD_UNCHANGED)
    intrinsics = json.loads((real / "intrinsics.json").read_text())
    folder = write_folder(tmp_path / "frames", [(rgb, depth)] * 2, intrinsics)
    from sid.perception.camera import Intrinsics

    bag = write_camera_bag(tmp_path / "bag", [(rgb, depth)] * 2, Intrinsics.from_dict(intrinsics), encoding="bgr8")
    outputs = []
    for source in (bag, folder):
        args = ["detect", "--source", str(source), "--model", str(model), "--no-keypoints", "--no-tracking"]
        assert main(args) == 0
        outputs.append([json.loads(line) for line in capsys.readouterr().out.splitlines()])
    from_bag, from_folder = outputs
    assert len(from_bag) == 2 and len(from_bag[0]["people"]) == 5
    assert [r["people"] for r in from_bag] == [r["people"] for r in from_folder]
    assert [r["groups"] for r in from_bag] == [r["groups"] for r in from_folder]


def test_a_colour_image_without_depth_is_reported_and_skipped(tmp_path: Path) -> None:
    pairs, synthetic = synthetic_pairs(3)
    bag = write_camera_bag(tmp_path / "bag", pairs, synthetic[0].calibration.color, skip_depth=[1])
    errors: list[FrameReadError] = []
    frames = list(skip_unreadable(open_source(str(bag)), errors.append))
    assert [f.index for f in frames] == [0, 2]
    assert [e.index for e in errors] == [1]
    assert "no depth image within 0.015 s" in str(errors[0])


def test_unsupported_encoding_is_a_frame_error_naming_it(tmp_path: Path) -> None:
    pairs, synthetic = synthetic_pairs(1)
    bag = write_camera_bag(tmp_path / "bag", pairs, synthetic[0].calibration.color, encoding="yuv422")
    with pytest.raises(FrameReadError, match="colour image encoding 'yuv422' is not supported"):
        next(iter(open_source(str(bag))))


def test_missing_topics_are_named(tmp_path: Path) -> None:
    pairs, synthetic = synthetic_pairs(1)
    bag = write_camera_bag(tmp_path / "bag", pairs, synthetic[0].calibration.color)
    with pytest.raises(SourceError, match=f"no sensor_msgs/msg/Image topic '/nowhere'.*{COLOR}"):
        Rosbag2Source(bag, color_topic="/nowhere")
    with pytest.raises(SourceError, match="does not exist"):
        open_source(str(tmp_path / "missing.mcap"))
    (tmp_path / "junk.mcap").write_bytes(b"not a bag")
    with pytest.raises(SourceError, match="cannot read rosbag2 recording"):
        open_source(str(tmp_path / "junk.mcap"))


def test_librealsense_db3_still_goes_to_the_realsense_source(tmp_path: Path) -> None:
    realsense()
    from sid.perception.camera import Calibration, Extrinsics, Intrinsics
    from sid.sources.librealsense import record_synthetic
    from sid.sources.realsense import RealSenseSource

    intr = Intrinsics(64, 48, 50.0, 50.0, 31.5, 23.5)
    pair = (np.zeros((48, 64, 3), np.uint8), np.full((48, 64), 1000, np.uint16))
    recording = record_synthetic(tmp_path / "rs.db3", [pair] * 2, Calibration(intr, intr, Extrinsics()))
    assert is_librealsense_recording(recording)
    source = open_source(str(recording), align="none")
    assert isinstance(source, RealSenseSource)
    frames = list(skip_unreadable(source, lambda error: None))  # played to the end (closing it earlier can hang)
    assert frames and frames[0].depth[10, 10] == pytest.approx(1.0)
    bag = write_camera_bag(
        tmp_path / "bag", synthetic_pairs(1)[0], synthetic_pairs(1)[1][0].calibration.color, mcap=False
    )
    assert not is_librealsense_recording(next(bag.glob("*.db3")))


def _frames_and_errors(spec: Path, **options: str) -> tuple[list[int], list[FrameReadError]]:
    errors: list[FrameReadError] = []
    frames = [f.index for f in skip_unreadable(open_source(str(spec), **options), errors.append)]
    return frames, errors


def test_colour_images_sharing_a_stamp_are_reported_as_skipped(tmp_path: Path) -> None:
    pairs, synthetic = synthetic_pairs(5)
    stamps = [100.0, 100.1, 100.1, 100.1, 100.3]  # frames 1 to 3 share one stamp: one is paired, two are reported
    bag = write_messages(tmp_path / "bag", camera_messages(pairs, synthetic[0].calibration.color, stamps=stamps))
    frames, errors = _frames_and_errors(bag)
    assert frames == [0, 1, 4]
    assert sorted(e.index for e in errors) == [2, 3]
    assert all("its colour image has the stamp of an earlier one (100.100000 s)" in str(e) for e in errors)
    assert len(frames) + len(errors) == 5  # every colour image is a frame or a line


def test_a_damaged_message_skips_its_frame_with_a_line(tmp_path: Path) -> None:
    pairs, synthetic = synthetic_pairs(3)
    messages = camera_messages(pairs, synthetic[0].calibration.color)
    topic, msgtype, time_ns, raw = messages[4]  # frame 1's colour image, cut in half
    assert topic == COLOR
    messages[4] = (topic, msgtype, time_ns, raw[: len(raw) // 2])
    bag = write_messages(tmp_path / "bag", messages)
    frames, errors = _frames_and_errors(bag)
    assert frames == [0, 2] and [e.index for e in errors] == [1]
    assert f"frame 1: {COLOR}: the message at 100.033 s (bag time) cannot be read (a damaged message:" in str(errors[0])


def test_an_empty_camera_info_is_skipped_with_a_warning_and_the_next_one_used(tmp_path: Path) -> None:
    pairs, synthetic = synthetic_pairs(2)
    messages = camera_messages(pairs, synthetic[0].calibration.color)
    topic, msgtype, time_ns, _ = messages[0]
    assert topic == INFO
    messages[0] = (topic, msgtype, time_ns, b"")
    bag = write_messages(tmp_path / "bag", messages)
    with pytest.warns(InputWarning, match=f"{INFO}: the message at 100.000 s .*cannot be read.*; skipped"):
        frames, errors = _frames_and_errors(bag)
    assert frames == [0, 1] and errors == []
    only_empty = write_messages(tmp_path / "empty", [m if m[0] != INFO else (*m[:3], b"") for m in messages])
    with (
        pytest.raises(
            SourceError, match=f"empty: {INFO}: none of its 2 message\\(s\\) can be used; the message at 100.000 s"
        ),
        pytest.warns(InputWarning),
    ):
        open_source(str(only_empty))


@pytest.mark.parametrize("namespace", ["/camera", "/robot/front", ""])
def test_realsense_topics_are_found_under_any_namespace(tmp_path: Path, namespace: str) -> None:
    pairs, synthetic = synthetic_pairs(2)
    bag = write_messages(tmp_path / "bag", camera_messages(pairs, synthetic[0].calibration.color, namespace=namespace))
    source = open_source(str(bag))
    assert isinstance(source, Rosbag2Source)
    assert (source.color.topic, source.depth.topic, source.info.topic) == (
        f"{namespace}/color/image_raw",
        f"{namespace}/aligned_depth_to_color/image_raw",
        f"{namespace}/color/camera_info",
    )
    assert [f.index for f in source] == [0, 1]


def test_topics_are_chosen_by_name_and_two_cameras_ask_for_the_option(tmp_path: Path, capsys) -> None:
    pairs, synthetic = synthetic_pairs(2)
    intr = synthetic[0].calibration.color
    messages = camera_messages(pairs, intr, namespace="/front") + camera_messages(pairs, intr, namespace="/back")
    bag = write_messages(tmp_path / "bag", messages)
    with pytest.raises(SourceError, match="several of the bag's .* topics end in 'color/image_raw'.*--color-topic"):
        open_source(str(bag))
    back = {"color_topic": "/back/color/image_raw", "depth_topic": "/back/aligned_depth_to_color/image_raw"}
    source = open_source(str(bag), **back)
    assert isinstance(source, Rosbag2Source) and source.info.topic == "/back/color/camera_info"
    argv = ["detect", "--source", str(bag), "--color-topic", back["color_topic"], "--depth-topic", back["depth_topic"]]
    assert main([*argv, "--info-topic", "/back/color/camera_info", "--frames", "1", "--no-tracking"]) == 2
    assert "a real source needs a pose model" in capsys.readouterr().err  # the topics were accepted; no model given
    folder = write_folder(tmp_path / "frames", pairs, intr.to_dict())
    with pytest.raises(
        SourceError, match=f"--color-topic: only rosbag2 recordings have topics to choose, and {folder}"
    ):
        open_source(str(folder), color_topic="/front/color/image_raw")


def test_damaged_files_are_named_with_what_is_wrong(tmp_path: Path) -> None:
    pairs, synthetic = synthetic_pairs(3)
    intr = synthetic[0].calibration.color
    db3 = next(write_camera_bag(tmp_path / "sqlite", pairs, intr, mcap=False).glob("*.db3"))
    half = tmp_path / "half.db3"
    half.write_bytes(db3.read_bytes()[: db3.stat().st_size // 2])
    with pytest.raises(SourceError, match=f"recording {half}: not a readable SQLite database \\(database disk image "):
        open_source(str(half))
    binary = write_camera_bag(tmp_path / "binary", pairs, intr)
    (binary / "metadata.yaml").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00")
    with pytest.raises(
        SourceError, match=f"rosbag2 metadata {binary / 'metadata.yaml'}: byte 0x89 at offset 0 .*UTF-8"
    ):
        open_source(str(binary))
    mcap = next(write_camera_bag(tmp_path / "mcap", pairs, intr).glob("*.mcap"))
    bare = tmp_path / "bare"
    bare.mkdir()
    (bare / "walk.mcap").write_bytes(mcap.read_bytes())
    with pytest.raises(
        SourceError, match=f"{bare}: holds walk.mcap but no metadata.yaml.*--source {bare / 'walk.mcap'}"
    ):
        open_source(str(bare))
    assert [f.index for f in open_source(str(bare / "walk.mcap"))] == [0, 1, 2]  # the file itself reads
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(mcap.read_bytes()[: mcap.stat().st_size // 2])
    with pytest.raises(SourceError, match=f"cannot read rosbag2 recording {cut}: "):
        open_source(str(cut))


@pytest.mark.parametrize("mcap", [True, False])
def test_a_file_damaged_inside_stops_the_source_naming_it(tmp_path: Path, mcap: bool) -> None:
    pairs, synthetic = synthetic_pairs(6)
    bag = write_camera_bag(tmp_path / "bag", pairs, synthetic[0].calibration.color, mcap=mcap)
    storage = next(bag.glob("*.mcap" if mcap else "*.db3"))
    raw = bytearray(storage.read_bytes())
    raw[len(raw) // 3 : len(raw) // 3 + 5000] = b"\xab" * 5000  # overwritten in the middle
    storage.write_bytes(bytes(raw))
    frames: list[Frame] = []
    with pytest.raises(SourceError, match=f"rosbag2 recording {bag} is damaged after its first \\d colour image"):
        frames.extend(skip_unreadable(open_source(str(bag)), lambda error: None))
    assert 0 < len(frames) < 6 and [f.index for f in frames] == list(range(len(frames)))  # the frames before it


def test_sid_detect_reports_each_bad_frame_of_a_bag_and_goes_on(tmp_path: Path, capsys) -> None:
    from tests.pose_models import build_yolo_pose_model

    pairs, synthetic = synthetic_pairs(5)
    stamps = [100.0, 100.1, 100.1, 100.3, 100.4]  # frame 2 repeats frame 1's stamp
    messages = camera_messages(pairs, synthetic[0].calibration.color, namespace="/camera", stamps=stamps)
    colour = [k for k, m in enumerate(messages) if m[0] == "/camera/color/image_raw"]
    topic, msgtype, time_ns, raw = messages[colour[3]]
    messages[colour[3]] = (topic, msgtype, time_ns, raw[:100])  # frame 3's colour message cut short
    bag = write_messages(tmp_path / "bag", messages)
    model = build_yolo_pose_model(tmp_path / "yolo.onnx", np.zeros((56, 10)))  # answers nobody: "no people"
    assert main(["detect", "--source", str(bag), "--model", str(model), "--no-tracking"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert (
        f"detect: frame 2: skipped, {bag}: frame 2: its colour image has the stamp of an earlier one (100.100000 s)"
        in err
    )
    assert any(
        line.startswith(f"detect: frame 3: skipped, {bag}: frame 3: /camera/color/image_raw: the message")
        for line in err
    )
    assert sorted(line.split()[2] for line in err if " skipped, " in line) == ["0:", "1:", "2:", "3:", "4:"]
    assert err[-1].startswith("detect: 0 frames with people, 5 skipped")


def test_compressed_image_topics_are_named_as_not_read(tmp_path: Path) -> None:
    """image_transport's compressed topics (sensor_msgs/CompressedImage) are not read: the error says so, whether the
    topic is found by its name or named with --color-topic, instead of saying that there is no colour topic."""
    pairs, synthetic = synthetic_pairs(1)
    messages = camera_messages(pairs, synthetic[0].calibration.color)
    compressed = COLOR + "/compressed"
    jpeg = cv2.imencode(".jpg", cv2.cvtColor(pairs[0][0], cv2.COLOR_RGB2BGR))[1].ravel()
    types = TYPES.types
    message = types["sensor_msgs/msg/CompressedImage"](
        header=header(100.0), format="rgb8; jpeg compressed bgr8", data=jpeg
    )
    raw = TYPES.serialize_cdr(message, "sensor_msgs/msg/CompressedImage")
    messages = [m for m in messages if m[0] != COLOR] + [(compressed, "sensor_msgs/msg/CompressedImage", 100, raw)]
    bag = write_messages(tmp_path / "bag", messages)
    not_read = f"{compressed} is a sensor_msgs/msg/CompressedImage topic; sid reads only raw sensor_msgs/msg/Image"
    with pytest.raises(SourceError, match=f"none of the bag's .*{not_read}.*docs/ros2.md"):
        open_source(str(bag))
    with pytest.raises(SourceError, match=f"topic '{compressed}' is a sensor_msgs/msg/CompressedImage topic; sid"):
        open_source(str(bag), color_topic=compressed)


def test_colour_stamps_going_back_are_named_as_such_not_as_missing_depth(tmp_path: Path) -> None:
    """A recording whose stamps go back (a clock reset, bags spliced): each colour image older than a frame already
    read is skipped saying so; its depth image is there, so "no depth image" would send the user the wrong way."""
    pairs, synthetic = synthetic_pairs(3)
    messages = camera_messages(pairs, synthetic[0].calibration.color, stamps=[100.2, 100.1, 100.3])
    frames, errors = _frames_and_errors(write_messages(tmp_path / "bag", messages))
    assert frames == [0, 2] and [e.index for e in errors] == [1]
    assert "frame 1: its colour image's stamp (100.100000 s) is older than an earlier frame's (100.200000 s)" in str(
        errors[0]
    )
    assert "no depth image" not in str(errors[0])
