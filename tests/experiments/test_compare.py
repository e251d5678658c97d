"""``sid compare``: the per-scenario table, summary.json and the chart, end to end."""

from __future__ import annotations

import json

import cv2
import numpy as np

from sid.cli import main
from sid.experiments.compare import BY_SCENARIO, format_summary, write_comparison
from sid.experiments.demo import DEMO_SCENARIO, demo_scenario
from sid.experiments.harness import prepare, run_matrix, summarise


def test_summary_table_and_chart(tmp_path):
    runs = run_matrix([prepare(demo_scenario())], ["grid", "rrtconnect"], runs=2, time_limits=(5.0,))
    rows = summarise([r.record() for r in runs], BY_SCENARIO)
    assert [(r["planner"], r["social_layer"]) for r in rows] == [
        ("grid", False), ("grid", True), ("rrtconnect", False), ("rrtconnect", True)
    ]  # fmt: skip
    without_grid = rows[0]
    assert without_grid["crossing_rate"] == 1.0 and without_grid["median_intrusion_m"] > 1.0
    table = format_summary(rows).splitlines()
    assert len(table) == 2 + 4 and "cost/grid" in table[0] and "rrtconnect" in table[-1]
    paths = write_comparison(runs, tmp_path, "test chart")
    assert json.loads(paths["summary"].read_text()) == rows
    chart = cv2.imread(str(paths["chart"]))
    assert chart is not None and chart.shape[1] >= 1200 and chart.shape[0] >= 400
    assert len(np.unique(chart.reshape(-1, 3), axis=0)) > 50  # drawn, not blank


def test_compare_command_writes_summary_and_chart(tmp_path, capsys):
    scenario = tmp_path / "demo.json"
    scenario.write_text(json.dumps(DEMO_SCENARIO))
    out = tmp_path / "cmp"
    args = ["compare", str(scenario), "--planners", "grid", "rrtconnect", "--runs", "1", "--time", "5"]
    assert main([*args, "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert "rrtconnect" in captured.out and "4/4" in captured.err  # the progress bar reaches the end
    assert len(json.loads((out / "summary.json").read_text())) == 4
    assert (out / "planners.png").stat().st_size > 10_000
    assert main(["compare", str(scenario), "--planners", "prmstar", "--out", str(out)]) == 2
    assert "PRM* is not available" in capsys.readouterr().err


def test_the_compare_example_is_the_demo_scenario_and_shows_the_layer(tmp_path, capsys):
    """examples/goal_behind_group.json is the demo's scenario: without the layer the path crosses the group."""
    from tests.conftest import REPO_ROOT

    example = REPO_ROOT / "examples" / "goal_behind_group.json"
    assert json.loads(example.read_text()) == json.loads(json.dumps(DEMO_SCENARIO))
    assert main(["compare", str(example), "--planners", "grid", "--runs", "1", "--out", str(tmp_path)]) == 0
    rows = {r["social_layer"]: r for r in json.loads((tmp_path / "summary.json").read_text())}
    assert rows[False]["crossing_rate"] == 1.0 and rows[False]["median_intrusion_m"] > 1.0
    assert rows[True]["crossing_rate"] == 0.0 and rows[True]["median_intrusion_m"] == 0.0
