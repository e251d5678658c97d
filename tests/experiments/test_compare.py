"""Planner comparison and benchmark plumbing on the demo scenario (tiny budgets: structure, not speed)."""

from __future__ import annotations

import json

from sid.cli import main
from sid.experiments.compare import format_summary, run_matrix, summarise, summary_chart
from sid.experiments.demo import DEMO_SCENARIO, demo_scenario
from sid.experiments.planner_bench import bench_planners, meets_target


def test_run_matrix_summary_table_and_chart():
    runs = run_matrix([demo_scenario()], ["grid", "rrtconnect"], runs=2, time_limits=(0.2,))
    assert len(runs) == 2 * (1 + 2)  # per social mode: grid once, rrtconnect with seeds 1 and 2
    grid = [r for r in runs if r.planner == "grid"]
    assert all(r.cost_ratio == 1.0 for r in grid)  # the reference is the grid planner's own path
    rows = summarise(runs)
    assert {(r["planner"], r["social"]) for r in rows} == {(p, s) for p in ("grid", "rrtconnect") for s in (0, 1)}
    without_grid = next(r for r in rows if r["planner"] == "grid" and not r["social"])
    assert without_grid["crossing_rate"] == 1.0 and without_grid["median_intrusion_m"] > 1.0
    table = format_summary(rows)
    assert "rrtconnect" in table and "cost/grid" in table
    chart = summary_chart(summarise(runs, by_scenario=False))
    assert chart.ndim == 3 and chart.shape[1] >= 1200


def test_bench_reports_per_budget_and_target():
    rows = bench_planners(budgets=(0.1,), runs=1, planners=["grid", "rrtconnect"])
    assert [(r["planner"], r["time_limit_s"]) for r in rows] == [("grid", 0.1), ("rrtconnect", 0.1)]
    assert meets_target(rows) is None  # the default planner was not run
    assert meets_target(rows, "grid") is None  # no row at the 0.5 s target budget


def test_compare_command_writes_summary_and_chart(tmp_path, capsys):
    scenario = tmp_path / "demo.json"
    scenario.write_text(json.dumps(DEMO_SCENARIO))
    out = tmp_path / "cmp"
    args = ["compare", str(scenario), "--planners", "grid", "rrtconnect", "--runs", "1", "--time", "0.2"]
    assert main([*args, "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert "rrtconnect" in captured.out and "4/4" in captured.err  # the progress bar reaches the end
    assert len(json.loads((out / "summary.json").read_text())) == 4
    assert (out / "planners.png").stat().st_size > 10_000
    assert main(["compare", str(scenario), "--planners", "prmstar", "--out", str(out)]) == 2
    assert "PRM* is not available" in capsys.readouterr().err
