"""The pictures in docs/images are what their commands (docs/images/regenerate.sh) draw today: each one redrawn
here and compared with the committed copy and the record beside it."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from sid.cli import main
from sid.experiments.simulate.loop import RunOptions
from sid.experiments.simulate.run import write_run
from sid.experiments.simulate.scenes import load_scene
from tests.conftest import REPO_ROOT

IMAGES = REPO_ROOT / "docs" / "images"
TIMES = {"planning_time_s", "solve_time_s"}  # wall-clock times: the only fields that change from run to run


def _same_picture(new: Path, committed: Path) -> None:
    a, b = cv2.imread(str(new)), cv2.imread(str(committed))
    assert a is not None and b is not None and a.shape == b.shape, f"{committed.name}: another size, redraw it"
    differ = np.any(a != b, axis=2).mean()  # the planning times in the demo's table are the only text that varies
    assert differ < 0.005, f"{committed.name}: {100 * differ:.1f} % of pixels differ: run docs/images/regenerate.sh"


def _without_times(record: dict) -> dict:
    return {k: _without_times(v) if isinstance(v, dict) else v for k, v in record.items() if k not in TIMES}


@pytest.mark.slow
def test_the_demo_picture_and_metrics_are_what_sid_demo_draws(tmp_path) -> None:
    assert main(["demo", "--out", str(tmp_path)]) == 0
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert _without_times(metrics) == _without_times(json.loads((IMAGES / "comparison.json").read_text()))
    _same_picture(tmp_path / "comparison.png", IMAGES / "comparison.png")


@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "social", "still_s"), [("simulate_paper", True, 3.0), ("simulate_paper_without", False, 9.0)]
)
def test_the_simulation_stills_are_what_sid_simulate_still_draws(tmp_path, name, social, still_s) -> None:
    """The run up to the still (the steps before it are the whole run's), its picture and the record's start."""
    world = load_scene("paper")
    world = dataclasses.replace(world, settings=dataclasses.replace(world.settings, time_limit_s=still_s + 0.05))
    record = write_run(world, RunOptions(social=social, planner="grid"), tmp_path, still_s=still_s)
    committed = json.loads((IMAGES / f"{name}.json").read_text())
    assert committed["social_layer"] is social and committed["seed"] == 0 and committed["planner"] == "grid"
    steps = len(record["trajectory"])
    assert record["trajectory"] == committed["trajectory"][:steps]
    _same_picture(tmp_path / "run.png", IMAGES / f"{name}.png")
