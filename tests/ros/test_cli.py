"""``sid ros`` as a command: the install hint without rclpy, the shipped-files folder, bad input."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from sid.cli import main
from sid.cli.common import ExitCode
from sid.distribution import install_hint
from sid.perception.frame import Frame


def test_without_rclpy_it_says_how_to_install_it(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setitem(sys.modules, "rclpy", None)  # import rclpy now raises ImportError
    assert main(["ros", "--source", "synthetic:S4"]) == ExitCode.MISSING_DEPENDENCY
    err = capsys.readouterr().err
    assert "rclpy" in err and install_hint("ros") in err and "docs/ros2.md" in err


def test_share_prints_the_folder_of_the_launch_and_yaml_files(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["ros", "--share"]) == 0
    folder = capsys.readouterr().out.strip()
    assert {p.name for p in Path(folder).iterdir()} >= {"sid.launch.py", "sid_params.yaml", "nav2_social_costmap.yaml"}


def test_camera_topics_need_a_pose_model(capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("rclpy", reason="rclpy is not installed (pip install 'sid-social[ros]' or source ROS 2)")
    assert main(["ros"]) == 2
    assert "--model FILE.onnx" in capsys.readouterr().err


def test_bad_parameter_is_reported(capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("rclpy", reason="rclpy is not installed (pip install 'sid-social[ros]' or source ROS 2)")
    code = main(["ros", "--source", "synthetic:S4", "--ros-args", "-p", "pose_source:=gps"])
    assert code == 2
    assert "pose_source must be one of auto, tf, odom, none, got 'gps'" in capsys.readouterr().err
    code = main(["ros", "--source", "synthetic:S4", "--ros-args", "-p", "costmap.resolution:=0.0"])
    assert code == 2
    assert "costmap.*" in capsys.readouterr().err


def test_a_bad_layer_instance_is_reported(capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("rclpy", reason="rclpy is not installed (pip install 'sid-social[ros]' or source ROS 2)")
    layers = ["-p", "costmap.plugins:=[tracked_people, near]", "-p", "costmap.near.plugin:=lidar"]
    assert main(["ros", "--source", "synthetic:S4", "--ros-args", *layers]) == ExitCode.USAGE
    assert "costmap.plugins: near is a lidar layer, which the node cannot feed" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--source", "synthetic:S4", "--rate", "nan"], "--rate: expected a finite frame rate in Hz >= 0, got 'nan'"),
        (["--source", "synthetic:S4", "--rate", "-1"], "--rate: expected a finite frame rate in Hz >= 0, got '-1'"),
        (
            ["--model", "pose.onnx", "--color-topic", "/front/color/image_raw"],
            "--color-topic: only a rosbag2 --source has topics to choose; the node subscribes to the topics of its "
            "ROS parameters: --ros-args -p color_topic:=/front/color/image_raw",
        ),
        (["--model", "pose.onnx", "--rate", "5"], "--rate: plays a --source; the camera topics come at their own rate"),
        (["--model", "pose.onnx", "--frames", "5"], "--frames: stops a --source; without one, stop the node"),
    ],
)
def test_options_of_a_source_are_refused_without_one_and_a_bad_rate_is_refused(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--color-topic`` (and the other topic options), ``--rate`` and ``--frames`` act on ``--source`` only:
    given without one they were ignored in silence (the node subscribed to the default topics). A rate of nan or
    below 0 was read as "as fast as possible"."""
    pytest.importorskip("rclpy", reason="rclpy is not installed (pip install 'sid-social[ros]' or source ROS 2)")
    if "nan" in argv or "-1" in argv:  # refused by argparse
        with pytest.raises(SystemExit) as stop:
            main(["ros", *argv])
        assert stop.value.code == ExitCode.USAGE
    else:
        assert main(["ros", *argv]) == ExitCode.USAGE
    assert message in capsys.readouterr().err


def test_a_tiny_rate_waits_without_overflowing_and_stops_with_the_node() -> None:
    """``--rate 1e-300`` is a period of 1e300 s: time.sleep raised OverflowError in the source's thread."""
    rclpy = pytest.importorskip("rclpy", reason="rclpy is not installed")
    import threading

    from sid.ros.node import SocialCostmapNode
    from sid.sources.synthetic import synthetic_source

    rclpy.init(args=["sid", "--ros-args", "-p", "pose_source:=none"])
    errors: list[BaseException] = []
    try:
        node = SocialCostmapNode(lambda frame: [], camera_topics=False)

        def feed() -> None:
            try:
                node.feed(synthetic_source("synthetic:S4", frames=2), rate=1e-300)
            except BaseException as exc:  # noqa: BLE001 - the test reports whatever the thread raised
                errors.append(exc)

        thread = threading.Thread(target=feed)
        thread.start()
        thread.join(timeout=3)
        assert thread.is_alive()  # waiting for the next frame
    finally:
        rclpy.shutdown()
    thread.join(timeout=5)
    node.node.destroy_node()
    assert not thread.is_alive() and errors == []


def test_a_source_that_stops_with_an_error_ends_the_run_with_exit_1(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A SourceError mid-stream (a camera failing again and again, a damaged bag) escaped the source's thread: a
    traceback, and the node kept spinning with nothing to publish. It now ends the run: ``source stopped``, exit 1."""
    rclpy = pytest.importorskip("rclpy", reason="rclpy is not installed")
    import threading

    import sid.cli.ros
    from sid.sources import SourceError
    from sid.sources.synthetic import synthetic_source

    def failing(spec: str, **options: object) -> Iterator[Frame]:
        yield from synthetic_source("synthetic:S4", frames=3)
        raise SourceError("bag.db3: database disk image is malformed")

    monkeypatch.setattr(sid.cli.ros, "open_source", failing)
    codes: list[int] = []
    run = threading.Thread(
        target=lambda: codes.append(main(["ros", "--source", "synthetic:S4", "--ros-args", "-p", "pose_source:=none"]))
    )
    run.start()
    run.join(timeout=30)
    if run.is_alive():  # still spinning: stop it so that the test fails instead of hanging
        rclpy.try_shutdown()
        run.join(timeout=10)
    err = capsys.readouterr().err
    assert codes == [ExitCode.FAILURE]
    assert "sid ros: source stopped: bag.db3: database disk image is malformed" in err
    assert "Traceback" not in err


@pytest.mark.parametrize(
    ("ros_args", "message"),
    [
        (["-p", "badformat"], "sid ros: --ros-args: Couldn't parse parameter override rule: '-p badformat'"),
        (["--params-file", "/nonexistent.yaml"], "sid ros: --ros-args: Couldn't parse params file"),
    ],
)
def test_ros_arguments_rcl_cannot_parse_are_bad_input(
    ros_args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """rclpy.init refusing ``--ros-args`` raised RCLError out of the command: a traceback and exit 1."""
    pytest.importorskip("rclpy", reason="rclpy is not installed")
    assert main(["ros", "--source", "synthetic:S4", "--ros-args", *ros_args]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert message in err and ", at " not in err
