"""Pictures and tables of a ``harness.Comparison``: its paths over the costmap (``sid.experiments.path_render``, BGR
uint8) with a metrics table under them, and the same table as plain text."""

from __future__ import annotations

import numpy as np

from sid.experiments.harness import LABELS, Comparison
from sid.experiments.path_render import WITH_COLOUR, WITHOUT_COLOUR, PathStyle, add_header, add_table, render_paths
from sid.scenario.obstacles import outline

__all__ = ["HEADER", "STYLES", "format_table", "metric_cells", "plan_picture"]

STYLES = {
    "without": PathStyle(LABELS["without"], WITHOUT_COLOUR, dashed=True),
    "with": PathStyle(LABELS["with"], WITH_COLOUR),
}
HEADER = ["path", "length", "in group zone", "crosses group", "closest person", "within 1.2 m", "planning"]


def metric_cells(m: dict, without: dict | None = None) -> list[str]:
    """A run's cells under ``HEADER`` (after "path"); the length gets its change over ``without``'s when given."""
    if not m["success"]:
        return ["no path", "-", "-", "-", "-", f"{m['planning_time_s']:.2f} s"]
    longer = ""
    if without is not None and without is not m and without.get("success"):
        longer = f" ({100 * (m['path_length_m'] / without['path_length_m'] - 1):+.0f} %)"
    return [
        f"{m['path_length_m']:.2f} m{longer}",
        f"{m['ospace_intrusion_m']:.2f} m",
        "yes" if m["crosses_group"] else "no",
        "-" if m["min_person_distance_m"] is None else f"{m['min_person_distance_m']:.2f} m",
        f"{100 * m['personal_space_fraction']:.0f} %",
        f"{m['planning_time_s']:.2f} s",
    ]


def _rows(comparison: Comparison) -> list[list[str]]:
    without = comparison.metrics.get("without")
    return [[LABELS[mode], *metric_cells(m, without)] for mode, m in comparison.metrics.items()]


def format_table(comparison: Comparison) -> str:
    """The comparison as a plain-text table (one row per mode)."""
    rows = [HEADER, *_rows(comparison)]
    widths = [max(len(r[i]) for r in rows) for i in range(len(HEADER))]
    lines = ["  ".join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)).rstrip() for row in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def plan_picture(comparison: Comparison, title: str, subtitle: str = "") -> np.ndarray:
    """BGR image: the costmap with the social layer when the comparison has a "with" run (else the one planned on),
    the scenario's declared obstacles outlined, every found path, people, group zones, robot and goal, a title, and
    the metrics table."""
    task = comparison.task
    background = task.costmaps["with" if "with" in comparison.runs else next(iter(comparison.runs))]
    paths = [(run.result.path, STYLES[mode]) for mode, run in comparison.runs.items() if run.result.success]
    outlines = [outline(ob) for ob in task.scenario.obstacles]
    img, _ = render_paths(background, paths, robot=task.scenario.robot, groups=task.groups, outlines=outlines)
    rows = [(STYLES[mode], row) for mode, row in zip(comparison.runs, _rows(comparison), strict=True)]
    return add_table(add_header(img, title, subtitle), HEADER, rows)
