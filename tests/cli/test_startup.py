"""``sid COMMAND`` imports the module of that command only: start-up time counts in ``sid detect``'s frame rate."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from sid.cli import COMMANDS, main
from tests.conftest import shared_path

REPO = Path(__file__).resolve().parents[2]
PROBE = """
import sys
from sid.cli import main
try:
    main([{command!r}, "--help"])
except SystemExit:
    pass
print(sorted(m for m in sys.modules if m.startswith("sid.cli.")))
"""


@pytest.mark.parametrize("command", ["groups", "track", "detect"])
def test_a_command_imports_only_its_own_module(command: str) -> None:
    done = subprocess.run([sys.executable, "-c", PROBE.format(command=command)], cwd=REPO, capture_output=True,
                          text=True, timeout=300, check=True)  # fmt: skip
    loaded = eval(done.stdout.strip().splitlines()[-1])  # a printed list of module names
    assert f"sid.cli.{command}" in loaded
    assert not {f"sid.cli.{other}" for other in COMMANDS if other != command} & set(loaded)


HEAVY = ("ompl", "sklearn", "planner", "sid.experiments.harness")


def test_detect_starts_without_the_planners_or_scikit_learn() -> None:
    """``sid detect`` needs neither OMPL nor the harness (planner options live in ``sid.cli.planning``), and
    scikit-learn only past 128 people in one call (``sid.perception.cluster``): most of its start-up, before."""
    probe = PROBE.replace('m.startswith("sid.cli.")', f"m.split('.')[0] in {HEAVY!r} or m in {HEAVY!r}")
    done = subprocess.run([sys.executable, "-c", probe.format(command="detect")], cwd=REPO, capture_output=True,
                          text=True, timeout=300, check=True)  # fmt: skip
    assert eval(done.stdout.strip().splitlines()[-1]) == []


def test_help_and_unknown_commands_still_list_every_command(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["--help"])
    listing = capsys.readouterr().out
    assert all(command in listing for command in COMMANDS)
    with pytest.raises(SystemExit):
        main(["nope"])
    assert "invalid choice: 'nope'" in capsys.readouterr().err


def test_tracking_a_sequence_does_not_import_the_assignment_solver() -> None:
    """scipy.optimize (0.7 s of imports) loads only when a frame's assignment is ambiguous (sid.tracking.assignment):
    a sequence of people standing apart never needs it."""
    probe = (
        "import contextlib, io, sys\n"
        "from sid.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    code = main(['detect', '--source', 'synthetic:S3', '--frames', '8'])\n"
        "print(code, 'scipy.optimize' in sys.modules)\n"
    )
    done = subprocess.run([sys.executable, "-c", probe], cwd=REPO, capture_output=True, text=True, timeout=300,
                          check=True)  # fmt: skip
    assert done.stdout.split() == ["0", "False"]


def test_loading_the_pose_model_prints_no_onnxruntime_warnings() -> None:
    """YOLO11n-pose's exporter sets an attribute deprecated since opset 13; onnxruntime's process-wide logger warns
    of it twice per session unless the command quiets it (``quiet_load_warnings``)."""
    folder = shared_path("data", "rgbd", "five_people")
    model = shared_path("models", "yolo11n-pose-256.onnx")
    done = subprocess.run([sys.executable, "-m", "sid", "detect", "--source", str(folder), "--model", str(model)],
                          cwd=REPO, capture_output=True, text=True, timeout=300, check=True)  # fmt: skip
    assert "onnxruntime" not in done.stderr
    assert len(done.stdout.splitlines()) == 1
