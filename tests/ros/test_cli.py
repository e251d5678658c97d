"""``sid ros`` as a command: the install hint without rclpy, the shipped-files folder, bad input."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from sid.cli import main
from sid.cli.common import ExitCode
from sid.distribution import install_hint


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
