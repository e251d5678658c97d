"""run_demo's outputs: the picture, metrics.json with its fixed keys, the scenario file, and the text table."""

from __future__ import annotations

import json

import cv2

from sid.experiments.demo import run_demo
from sid.experiments.harness import LABELS
from sid.experiments.path_metrics import FIXED_KEYS
from sid.experiments.plan_pictures import format_table
from sid.scenario.loader import load_scenario


def test_run_demo_writes_picture_metrics_and_scenario(tmp_path):
    lines: list[str] = []
    comparison = run_demo(tmp_path / "out", max_iterations=3000, progress=lines.append)
    out = tmp_path / "out"
    picture = cv2.imread(str(out / "comparison.png"))
    assert picture is not None and picture.shape[0] > 600 and picture.shape[1] > 900
    metrics = json.loads((out / "metrics.json").read_text())
    assert list(metrics) == ["without", "with"]
    for side in metrics.values():
        assert set(FIXED_KEYS) <= set(side)
        assert isinstance(side["success"], bool) and isinstance(side["crosses_group"], bool)
    assert metrics == json.loads(json.dumps(comparison.metrics))
    assert load_scenario(out / "scenario.json").people == comparison.task.scenario.people
    assert lines[0].startswith("[1/2] planning without") and lines[2].startswith("[2/2] planning with")
    assert "bitstar: " in lines[1] and "bitstar: " in lines[3]
    table = format_table(comparison).splitlines()
    assert "in group zone" in table[0]
    assert table[2].startswith(LABELS["without"]) and table[3].startswith(LABELS["with"])
    assert " (+" in table[3]  # the detour over the path without recognition
