"""``sid simulate``: one run with its files, the scene list, bad input."""

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from sid.cli import main
from sid.cli.common import ExitCode
from sid.experiments.simulate.video import VideoWriter
from tests.experiments.simulate.tiny import TINY

RUN_KEYS = {"success", "collisions", "time_to_goal_s", "path_length_m", "min_person_distance_m",
            "ospace_intrusion_m", "crosses_group", "replans", "trajectory"}  # fmt: skip


@pytest.fixture
def scene(tmp_path):
    path = tmp_path / "tiny.json"
    path.write_text(json.dumps(TINY | {"simulation": {"max_speed": 1.0, "time_limit_s": 0.5}}))
    return str(path)


def test_a_run_writes_run_json_and_a_video(scene, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["simulate", scene, "--out", str(out), "--gif"]) == ExitCode.NO_PATH  # the time limit ends it first
    record = json.loads((out / "run.json").read_text())
    assert set(record) >= RUN_KEYS
    assert record["success"] is False and record["reason"].startswith("time limit (0.5 s)")
    assert len(record["trajectory"]) == 6 and record["trajectory"][0] == [0.0, 0.0, 0.0, 0.0]
    images = _frames(out / "run.mp4")
    assert len(images) == 5 and images[0].shape[1] > 1000  # the map, its legend and the camera column
    assert (out / "run.gif").stat().st_size > 0
    printed = capsys.readouterr().out
    assert "ospace_intrusion_m" in printed and f"wrote {out / 'run.mp4'}" in printed


def test_a_goal_inside_a_groups_zone_is_warned_of_as_sid_plan_does(tmp_path, capsys):
    # the run entered the pair's zone (crosses_group true, ospace_intrusion_m > 0) without a word on why
    path = tmp_path / "goal_in_zone.json"
    robot = TINY["robot"] | {"goal": [2.0, 0.0, 0.0]}  # between the pair, who face each other
    path.write_text(json.dumps(TINY | {"robot": robot, "simulation": {"time_limit_s": 0.2}}))
    assert main(["simulate", str(path), "--no-social", "--out", str(tmp_path / "out")]) == ExitCode.NO_PATH
    assert (
        "sid simulate: warning: the goal lies inside the interaction zone of group (1, 2): the path has to enter it"
        in (capsys.readouterr().err)
    )


def test_without_out_the_files_go_to_the_default_folder(scene, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", scene, "--no-social"]) == ExitCode.NO_PATH
    printed = capsys.readouterr().out
    assert "collisions" in printed and f"wrote {Path('sid-simulate') / 'run.json'}" in printed
    assert sorted(p.name for p in (tmp_path / "sid-simulate").iterdir()) == ["run.json", "run.mp4"]


def test_list_and_bad_input(capsys, tmp_path):
    assert main(["simulate", "--list"]) == 0
    assert "paper " in capsys.readouterr().out
    assert main(["simulate", "nowhere"]) == 2
    assert "neither a built-in scene" in capsys.readouterr().err
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(TINY | {"simulation": {"max_sped": 1}}))
    assert main(["simulate", str(bad)]) == 2
    assert "simulation.max_sped: unknown field" in capsys.readouterr().err
    assert main(["simulate", "paper", "--model", str(tmp_path / "none.onnx")]) == 2
    assert main(["simulate"]) == 2


def test_the_video_writer_pads_odd_frames(tmp_path):
    frame = np.zeros((31, 41, 3), np.uint8)
    frame[:, :20] = (0, 0, 255)  # BGR red on the left
    with VideoWriter(tmp_path / "v.mp4", 10.0) as writer:
        for _ in range(3):
            writer.add(frame)
    frames = _frames(tmp_path / "v.mp4")
    assert len(frames) == 3 and frames[0].shape == (32, 42, 3)
    assert frames[0][15, 5, 2] > 200 and frames[0][15, 5, 0] < 60  # BGR: red stays red


def _frames(path: Path) -> list[np.ndarray]:
    """Every frame of a video (BGR), read back with OpenCV."""
    reader, frames = cv2.VideoCapture(str(path)), []
    while True:
        ok, frame = reader.read()
        if not ok:
            return frames
        frames.append(frame)


def test_still_writes_the_picture_at_that_time_and_the_gif_is_full_size(scene, tmp_path):
    from PIL import Image

    out = tmp_path / "out"
    assert main(["simulate", scene, "--out", str(out), "--gif", "--still", "0.2"]) == ExitCode.NO_PATH
    still = cv2.imread(str(out / "run.png"))
    height, width = _frames(out / "run.mp4")[0].shape[:2]
    assert still is not None  # the video's frames are one size, padded to even sides for 4:2:0 video
    assert 0 <= width - still.shape[1] <= 1 and 0 <= height - still.shape[0] <= 1
    with Image.open(out / "run.gif") as gif:
        assert gif.size == (still.shape[1], still.shape[0])  # text as legible as the video's


def test_a_still_after_the_runs_end_shows_the_last_step_and_says_so(scene, tmp_path, capsys):
    """--still 60 on a run that ends at 0.5 s drew the last step without a word."""
    out = tmp_path / "out"
    assert main(["simulate", scene, "--out", str(out), "--still", "60"]) == ExitCode.NO_PATH
    assert cv2.imread(str(out / "run.png")) is not None
    assert "sid simulate: warning: run.png: the run's last step is at t = 0.4 s, before 60 s: it shows that step" in (
        capsys.readouterr().err
    )
    assert main(["simulate", scene, "--out", str(out), "--still", "0.2"]) == ExitCode.NO_PATH
    assert "warning" not in capsys.readouterr().err
