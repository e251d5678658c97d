"""``sid compare``'s outputs: every planner x with/without the social layer x K seeds on scenarios
(``sid.experiments.harness.run_matrix``), summarised per scenario as a text table and ``summary.json``, and over all
scenarios as a chart.

Each run's cost J is divided by the cost of the grid planner's path (Dijkstra + any-angle shortcut + the same
smoothing) on the same costmap: the reference, as close to the optimum as this project gets deterministically
(a ratio below 1 means the sampling planner found a slightly better local optimum). The raw ratio is that of the
planner's own path before smoothing (for the grid planner: its 8-connected path).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from sid.experiments.charts import PLANNER_PANELS, bar_chart
from sid.experiments.harness import Run, summarise

__all__ = ["BY_SCENARIO", "CHART_NOTE", "format_summary", "write_comparison"]

BY_SCENARIO = ("scenario", "time_limit_s", "planner")


def _fmt(value: float | None, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def format_summary(rows: Sequence[dict]) -> str:
    """A plain-text table of ``summarise(records, BY_SCENARIO)`` rows."""
    header = ["scenario", "social", "budget", "planner", "runs", "success", "time (med)", "cost/grid", "worst",
              "raw/grid", "in zone (med)", "crosses"]  # fmt: skip
    table = [header] + [
        [
            row["scenario"],
            "with" if row["social_layer"] else "without",
            f"{row['time_limit_s']:g} s",
            row["planner"],
            str(row["runs"]),
            f"{100 * row['success_rate']:.0f} %",
            _fmt(row["median_planning_time_s"], ".3f") + " s",
            _fmt(row["median_cost_ratio"], ".3f"),
            _fmt(row["worst_cost_ratio"], ".3f"),
            _fmt(row["median_raw_cost_ratio"], ".3f"),
            _fmt(row["median_intrusion_m"], ".2f") + " m",
            "-" if row["crossing_rate"] is None else f"{100 * row['crossing_rate']:.0f} %",
        ]
        for row in rows
    ]
    widths = [max(len(r[i]) for r in table) for i in range(len(header))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip() for r in table]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


CHART_NOTE = (
    "Medians over seeds and scenarios. Cost: the path's cost J over the grid planner's on the same costmap. "
    "n/a: no successful run, or a 0 m grid path to compare with."
)


def write_comparison(runs: Sequence[Run], out_dir: str | Path, title: str) -> dict[str, Path]:
    """Write ``summary.json`` (rows per scenario, budget, planner and costmap) and ``planners.png`` (the chart of the
    rows over all scenarios) into ``out_dir`` (created if missing); returns their paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    records = [run.record() for run in runs]
    paths = {"summary": out / "summary.json", "chart": out / "planners.png"}
    paths["summary"].write_text(json.dumps(summarise(records, BY_SCENARIO), indent=2, allow_nan=False) + "\n")
    bar_chart(summarise(records, ("time_limit_s", "planner")), PLANNER_PANELS, paths["chart"], title, CHART_NOTE)
    return paths
