"""Ordinary mistakes on the command line end in one line naming the problem and exit code 2, never a traceback.

Each case is a malformed input kept as a regression fixture (issue 15): an ``--out`` that cannot be a folder, a seed
OMPL cannot take, a calibration file with a mistyped field, and where ``sid bench`` looks for pose models.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from planner.facade import MAX_SEED
from sid.cli import bench, main
from tests.conftest import REPO_ROOT
from tests.pose_models import build_yolo_pose_model

SCENARIO = str(REPO_ROOT / "examples" / "conversation.json")

# Every command with --out, with arguments that would otherwise start real work (a plan, a benchmark, a study).
COMMANDS = {
    "detect": ["detect", "--source", "synthetic:S1", "--frames", "1"],
    "plan": ["plan", SCENARIO, "--planner", "grid"],
    "costmap": ["costmap", SCENARIO],
    "demo": ["demo", "--planner", "grid"],
    "bench": ["bench", "--quick", "--only", "group/2", "--shared", "/nonexistent"],
    "compare": ["compare", SCENARIO, "--planners", "grid", "--runs", "1"],
    "reproduce": ["reproduce", "table1", "--quick", "--scenarios", "S1"],
}


def one_line_error(capsys: pytest.CaptureFixture[str], command: str) -> str:
    """The single stderr line of a refused run, after checking that nothing was planned, run or written."""
    captured = capsys.readouterr()
    lines = [line for line in captured.err.splitlines() if not line.startswith("sid bench: note:")]
    assert len(lines) == 1, captured.err
    assert lines[0].startswith(f"sid {command}: --out "), lines[0]
    assert "Traceback" not in captured.err and "wrote" not in captured.out and "planning" not in captured.out
    return lines[0]


@pytest.mark.parametrize("command", COMMANDS)
def test_out_that_is_a_file_is_refused_before_any_work(command, tmp_path, capsys):
    blocker = tmp_path / "results.txt"
    blocker.write_text("keep me")
    assert main([*COMMANDS[command], "--out", str(blocker)]) == 2
    assert one_line_error(capsys, command).endswith(f"{blocker}: is a file, not a folder")
    assert blocker.read_text() == "keep me"


@pytest.mark.parametrize("command", COMMANDS)
@pytest.mark.parametrize("empty", ["", " "])
def test_an_empty_out_is_refused_rather_than_taken_for_the_working_folder(
    command, empty, tmp_path, capsys, monkeypatch
):
    # An unset variable in a script (--out "$OUT") wrote into the working folder, and sid detect cleared its files.
    monkeypatch.chdir(tmp_path)
    assert main([*COMMANDS[command], "--out", empty]) == 2
    assert one_line_error(capsys, command).endswith(": an empty path; give a folder (. for the working folder)")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("command", ["plan", "detect", "bench"])
def test_out_below_a_file_is_refused(command, tmp_path, capsys):
    blocker = tmp_path / "results.txt"
    blocker.write_text("")
    assert main([*COMMANDS[command], "--out", str(blocker / "run1")]) == 2
    assert one_line_error(capsys, command).endswith(f"cannot create the folder, {blocker} is a file")


@pytest.mark.skipif(
    not Path("/proc/self").is_dir(), reason="needs Linux /proc (a folder nobody, not even root, writes)"
)
@pytest.mark.parametrize("command", ["plan", "costmap", "demo"])
def test_unwritable_out_is_refused(command, capsys):
    assert main([*COMMANDS[command], "--out", "/proc/sid-out"]) == 2
    assert "cannot write in /proc to create the folder" in one_line_error(capsys, command)


def test_out_check_creates_nothing(tmp_path, capsys):
    """A refused run (here: a bad scenario) leaves no empty output folder behind."""
    bad = tmp_path / "bad.json"
    bad.write_bytes(b"\xff\xfe\x00garbage")
    assert main(["plan", str(bad), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bad.json: cannot read scenario file: byte 0xff at offset 0" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("seed", ["99999999999999999999", str(MAX_SEED + 1), "0", "-3", "abc", "1.5"])
def test_seed_outside_what_ompl_takes_names_the_range(seed, tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["plan", SCENARIO, "--out", str(tmp_path), "--seed", seed])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert f"argument --seed: expected a whole number from 1 to {MAX_SEED}, got '{seed}'" in err
    assert "Traceback" not in err and not (tmp_path / "path.json").exists()


@pytest.mark.parametrize("command", [["eval", "crowd", "DIR"], ["eval", "tracking"], ["reproduce", "table1"]])
@pytest.mark.parametrize("seed", ["-1", "1.5", "abc"])
def test_a_noise_seed_that_numpy_cannot_take_is_refused_naming_the_option(command, seed, capsys):
    # numpy's generators take any whole number >= 0; -1 used to end in numpy's "expected non-negative integer".
    with pytest.raises(SystemExit) as stop:
        main([*command, "--seed", seed])
    assert stop.value.code == 2
    assert f"argument --seed: expected a whole number >= 0, got '{seed}'" in capsys.readouterr().err


@pytest.mark.parametrize("still", ["nan", "-1", "inf", "x"])
def test_a_still_time_that_is_not_a_time_is_refused(still, tmp_path, capsys):
    # --still nan used to pass silently: run.png showed the first step.
    with pytest.raises(SystemExit) as stop:
        main(["simulate", "pair", "--out", str(tmp_path), "--still", still])
    assert stop.value.code == 2
    assert f"argument --still: expected a finite number of seconds >= 0, got '{still}'" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("command", ["plan", "demo", "compare"])
@pytest.mark.parametrize("budget", ["nan", "-1", "0", "inf"])
def test_a_time_budget_that_is_not_one_is_refused_before_any_output(command, budget, tmp_path, capsys):
    # The planner refused it, but only after "planning ... (nan s budget) ..." was on standard output.
    argv = [command] + ([] if command == "demo" else [SCENARIO])
    with pytest.raises(SystemExit) as stop:
        main([*argv, "--out", str(tmp_path / "out"), "--time", budget])
    assert stop.value.code == 2
    printed = capsys.readouterr()
    assert f"argument --time: expected a positive number of seconds, got '{budget}'" in printed.err
    assert printed.out == "" and not (tmp_path / "out").exists()


def test_the_planner_itself_refuses_a_seed_ompl_cannot_take():
    import sid

    scenario = sid.load_scenario(SCENARIO)
    problem = sid.planning_problem(scenario, sid.build_costmap(scenario).master)
    with pytest.raises(ValueError, match=f"seed must be a whole number from 1 to {MAX_SEED}"):
        sid.plan(problem, planner="rrtconnect", seed=MAX_SEED + 1)


def write_frame_folder(folder: Path, calibration: object) -> Path:
    folder.mkdir()
    assert cv2.imwrite(str(folder / "color.png"), np.zeros((48, 64, 3), np.uint8))
    assert cv2.imwrite(str(folder / "depth.png"), np.full((48, 64), 2000, np.uint16))
    (folder / "intrinsics.json").write_text(json.dumps(calibration))
    return folder


GOOD_INTRINSICS = {"width": 64, "height": 48, "fx": 50.0, "fy": 50.0, "cx": 31.5, "cy": 23.5}


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"fx": None}, "intrinsics: fx must be a number, got null"),
        ({"fx": [525]}, "intrinsics: fx must be a number, got [525]"),
        ({"width": None}, "intrinsics: width must be a number, got null"),
        ({"depth_scale_m": None}, "depth_scale_m must be a number, got null"),
        ({"depth_scale_m": [0.001]}, "depth_scale_m must be a number, got [0.001]"),
        ({"color": "abc"}, 'color: expected an object with width, height, fx, fy, cx, cy, got "abc"'),
    ],
)
def test_detect_on_a_folder_with_a_mistyped_calibration(change, message, tmp_path, capsys):
    folder = write_frame_folder(tmp_path / "frames", GOOD_INTRINSICS | change)
    model = build_yolo_pose_model(tmp_path / "yolo.onnx", np.zeros((56, 10)))
    assert main(["detect", "--source", str(folder), "--model", str(model)]) == 2
    err = capsys.readouterr().err
    # one error line; a warning may come first (a flat object beside a "color" key: its fields are not read)
    errors = [line for line in err.splitlines() if ": warning: " not in line]
    assert len(errors) == 1 and "intrinsics.json" in errors[0] and message in errors[0] and "Traceback" not in err


def test_detect_without_pyrealsense2_says_why(tmp_path, monkeypatch, capsys):
    """As on a machine without libusb-1.0: one line saying what to install."""
    monkeypatch.setitem(sys.modules, "pyrealsense2", None)
    for name in ("sid.sources.realsense", "sid.sources.librealsense"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    model = build_yolo_pose_model(tmp_path / "yolo.onnx", np.zeros((56, 10)))
    assert main(["detect", "--source", "realsense", "--model", str(model)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "need pyrealsense2, which cannot be loaded" in err and "libusb-1.0-0" in err


def test_bench_without_pose_models_names_the_folder_it_looked_in(tmp_path, capsys):
    assert main(["bench", "--list", "--shared", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert f"sid bench: note: pose benchmarks skipped: no .onnx model in {tmp_path / 'models'}" in err


def test_bench_finds_shared_next_to_the_repository_after_pip_install(tmp_path, monkeypatch):
    """After `pip install .` the module lives in site-packages: ../shared is found from the current directory's
    checkout, and $SID_SHARED overrides both."""
    checkout = tmp_path / "work" / "sid-repo"
    (checkout / "sid").mkdir(parents=True)
    (checkout / "sid" / "__init__.py").write_text("")
    (checkout / "pyproject.toml").write_text("")
    (checkout / "docs").mkdir()
    site = tmp_path / "venv" / "lib" / "site-packages" / "sid" / "cli" / "bench.py"
    monkeypatch.setattr(bench, "__file__", str(site))
    monkeypatch.delenv(bench.SHARED_ENV, raising=False)
    monkeypatch.chdir(checkout / "docs")
    assert bench.default_shared() == tmp_path / "work" / "shared"
    monkeypatch.chdir(tmp_path)
    assert bench.default_shared() == tmp_path.parent / "shared"  # no checkout: ../shared from here
    monkeypatch.setenv(bench.SHARED_ENV, str(tmp_path / "data"))
    assert bench.default_shared() == tmp_path / "data"


def test_bench_help_documents_sid_shared():
    out = subprocess.run(
        [sys.executable, "-m", "sid", "bench", "--help"], capture_output=True, text=True, cwd=REPO_ROOT, check=True
    ).stdout
    assert "$SID_SHARED" in " ".join(out.split())


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--cost-weight", "-1", "argument --cost-weight: expected a number from 0 to 1000, got '-1'"),
        ("--cost-weight", "nan", "argument --cost-weight: expected a number from 0 to 1000, got 'nan'"),
        ("--iterations", "0", "argument --iterations: expected a whole number >= 1, got '0'"),
    ],
)
def test_planning_options_are_refused_before_anything_is_planned_or_printed(option, value, message, capsys):
    # They were refused by the planner, after "planning ... with bitstar" was printed, in the planner's own words.
    with pytest.raises(SystemExit) as stop:
        main(["plan", SCENARIO, option, value])
    captured = capsys.readouterr()
    assert (
        stop.value.code == 2 and captured.out == "" and captured.err.splitlines()[-1] == f"sid plan: error: {message}"
    )
