"""run_demo's outputs: the picture, metrics.json with its fixed keys, the scenario file, and the text table."""

from __future__ import annotations

import json

import cv2

from planner.metrics import FIXED_KEYS
from sid.experiments.demo import LABELS, format_table, run_demo
from sid.scenario.loader import load_scenario


def test_run_demo_writes_picture_metrics_and_scenario(tmp_path):
    lines: list[str] = []
    comparison = run_demo(tmp_path / "out", max_iterations=3000, progress=lines.append)
    out = tmp_path / "out"
    picture = cv2.imread(str(out / "comparison.png"))
    assert picture is not None and picture.shape[0] > 600 and picture.shape[1] > 900
    metrics = json.loads((out / "metrics.json").read_text())
    assert set(metrics) == {"without", "with"}
    for side in metrics.values():
        assert set(FIXED_KEYS) <= set(side)
        assert isinstance(side["success"], bool) and isinstance(side["crosses_group"], bool)
    assert metrics == json.loads(json.dumps(comparison.metrics))
    assert load_scenario(out / "scenario.json").people == comparison.scenario.people
    assert any("[1/2]" in line for line in lines) and any("[2/2]" in line for line in lines)
    table = format_table(comparison)
    assert LABELS["without"] in table and LABELS["with"] in table and "in group zone" in table
