"""Planner comparison: every planner x with/without the social layer x K seeds on scenarios, against the grid.

Each run's cost J is divided by the cost of the grid planner's path (Dijkstra + any-angle shortcut + the same
smoothing) on the same costmap: the reference, as close to the optimum as this project gets deterministically
(a ratio below 1 means the sampling planner found a slightly better local optimum). The raw ratio is that of the
planner's own path before smoothing (for the grid planner: its 8-connected path). Runs use seeds 1..K, so a
comparison is repeatable up to where time budgets cut the planners.
"""

from __future__ import annotations

import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from planner.facade import PLANNERS, plan, resolve_planner
from planner.metrics import result_metrics
from planner.problem import DEFAULT_COST_WEIGHT
from sid.perception.groups import detect_groups
from sid.scenario.build import build_costmap, planning_problem
from sid.scenario.loader import Scenario

Progress = Callable[[int, int, str], None]
"""progress(done, total, what): called before each run and once at the end."""


@dataclass(frozen=True)
class Run:
    """One planner run: where, how, its metrics (``planner.metrics.result_metrics``) and J / J_grid."""

    scenario: str
    social: bool
    planner: str
    seed: int | None
    time_limit: float
    metrics: dict
    cost_ratio: float | None
    raw_cost_ratio: float | None  # the planner's own path, before smoothing


def run_matrix(
    scenarios: Sequence[Scenario],
    planners: Sequence[str] = PLANNERS,
    runs: int = 3,
    time_limits: Sequence[float] = (0.5,),
    social_modes: Sequence[bool] = (False, True),
    cost_weight: float = DEFAULT_COST_WEIGHT,
    progress: Progress | None = None,
) -> list[Run]:
    """Run every planner (grid: once, it is deterministic) with seeds 1..``runs`` for every time limit, social mode
    and scenario. Raises ``PlanningError`` naming the scenario when its task is impossible."""
    names = [resolve_planner(p) for p in planners]
    if runs < 1:
        raise ValueError(f"runs must be at least 1, got {runs}")
    jobs = [
        (scenario, social, name, seed, limit)
        for scenario in scenarios
        for social in social_modes
        for limit in time_limits
        for name in names
        for seed in ([None] if name == "grid" else range(1, runs + 1))
    ]
    setups: dict[tuple[int, bool], tuple] = {}
    out: list[Run] = []
    for done, (scenario, social, name, seed, limit) in enumerate(jobs):
        if progress:
            progress(done, len(jobs), f"{scenario.name} {'with' if social else 'without'} social layer: {name}")
        key = (id(scenario), social)
        if key not in setups:
            groups = detect_groups(scenario.people, scenario.group_params)
            layered = build_costmap(scenario, social=social, groups=groups if social else [])
            problem = planning_problem(scenario, layered.master, cost_weight)
            try:
                reference = plan(problem, "grid")
            except ValueError as exc:  # PlanningError: say which scenario
                raise type(exc)(f"{scenario.name}: {exc}") from exc
            setups[key] = (groups, layered, problem, reference.cost)
        groups, layered, problem, reference_cost = setups[key]
        result = plan(problem, name, time_limit=limit, seed=seed)
        metrics = result_metrics(result, scenario.people, groups, layered.master)
        ratio = result.cost / reference_cost if result.success else None
        raw_ratio = result.raw_cost / reference_cost if result.success else None
        out.append(Run(scenario.name, social, name, seed, limit, metrics, ratio, raw_ratio))
    if progress:
        progress(len(jobs), len(jobs), "done")
    return out


def _median(values: list) -> float | None:
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def summarise(runs: Sequence[Run], by_scenario: bool = True) -> list[dict]:
    """One row per (scenario, social, time limit, planner): runs, success rate, median planning time (s), median and
    worst cost ratio, median o-space intrusion (m) and the fraction of runs crossing a group."""
    groups: dict[tuple, list[Run]] = {}
    for run in runs:
        key = (run.scenario if by_scenario else "all", run.social, run.time_limit, run.planner)
        groups.setdefault(key, []).append(run)
    rows = []
    for (scenario, social, limit, planner), members in groups.items():
        ok = [r for r in members if r.metrics["success"]]
        ratios = [r.cost_ratio for r in ok]
        rows.append(
            {
                "scenario": scenario,
                "social": social,
                "time_limit_s": limit,
                "planner": planner,
                "runs": len(members),
                "success_rate": len(ok) / len(members),
                "median_time_s": _median([r.metrics["planning_time_s"] for r in members]),
                "median_cost_ratio": _median(ratios),
                "worst_cost_ratio": max(ratios) if ratios else None,
                "median_raw_cost_ratio": _median([r.raw_cost_ratio for r in ok]),
                "median_intrusion_m": _median([r.metrics["ospace_intrusion_m"] for r in ok]),
                "crossing_rate": sum(bool(r.metrics["crosses_group"]) for r in ok) / len(ok) if ok else None,
            }
        )
    return rows


def _fmt(value: float | None, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def format_summary(rows: Sequence[dict]) -> str:
    """A plain-text table of ``summarise`` rows."""
    header = ["scenario", "social", "budget", "planner", "runs", "success", "time (med)", "cost/grid", "worst",
              "raw/grid", "in zone (med)", "crosses"]  # fmt: skip
    table = [header] + [
        [
            row["scenario"],
            "with" if row["social"] else "without",
            f"{row['time_limit_s']:g} s",
            row["planner"],
            str(row["runs"]),
            f"{100 * row['success_rate']:.0f} %",
            _fmt(row["median_time_s"], ".3f") + " s",
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


_BAR_COLOURS = {False: (60, 60, 215), True: (170, 20, 150)}  # BGR: without red, with purple (as in the demo)
_TEXT = (40, 40, 40)
_FONT = cv2.FONT_HERSHEY_SIMPLEX


def _bar_panel(
    rows: Sequence[dict], value: Callable[[dict], float | None], title: str, fmt: str, size: tuple[int, int]
):
    """One bar chart: a pair of bars (without, with the social layer) per planner; negative values sit at zero."""
    width, height = size
    img = np.full((height, width, 3), 255, np.uint8)
    cv2.putText(img, title, (50, 26), _FONT, 0.5, _TEXT, 1, cv2.LINE_AA)
    planners = list(dict.fromkeys(r["planner"] for r in rows))
    values = [v for v in (value(r) for r in rows) if v is not None]
    top = max(max(values, default=0.0) * 1.2, 1e-3)
    left, right, y0, y1 = 50, width - 12, 44, height - 70
    cv2.line(img, (left, y1), (right, y1), _TEXT, 1)
    cv2.line(img, (left, y0), (left, y1), _TEXT, 1)
    for tick in np.linspace(0, top, 5):
        v = int(y1 - (y1 - y0) * tick / top)
        cv2.line(img, (left - 4, v), (left, v), _TEXT, 1)
        cv2.putText(img, format(tick, fmt), (4, v + 4), _FONT, 0.35, _TEXT, 1, cv2.LINE_AA)
    slot = (right - left) / max(1, len(planners))
    for i, planner in enumerate(planners):
        for j, social in enumerate((False, True)):
            row = next((r for r in rows if r["planner"] == planner and r["social"] == social), None)
            v_ = None if row is None else value(row)
            if v_ is None:
                continue
            x0 = int(left + i * slot + slot * (0.12 + 0.38 * j))
            x1 = int(x0 + slot * 0.36)
            v = int(y1 - (y1 - y0) * max(v_, 0.0) / top)
            cv2.rectangle(img, (x0, v), (x1, y1), _BAR_COLOURS[social], -1)
            label = format(v_, fmt)
            label = format(0.0, fmt) if float(label) == 0 else label  # no "-0.0"
            cv2.putText(img, label, (x0 - 2, v - 4), _FONT, 0.33, _TEXT, 1, cv2.LINE_AA)
        centre = int(left + (i + 0.5) * slot)
        for k, part in enumerate(planner.split("_")):
            w = cv2.getTextSize(part, _FONT, 0.4, 1)[0][0]
            cv2.putText(img, part, (centre - w // 2, y1 + 18 + 16 * k), _FONT, 0.4, _TEXT, 1, cv2.LINE_AA)
    return img


def summary_chart(rows: Sequence[dict], title: str = "Planner comparison (medians over runs and scenarios)"):
    """BGR bar charts of ``summarise(runs, by_scenario=False)`` rows for one time limit, per planner without and
    with the social layer: median planning time, median cost above the grid reference, median o-space intrusion."""
    size = (440, 360)
    panels = [
        _bar_panel(rows, lambda r: r["median_time_s"], "median planning time (s)", ".2f", size),
        _bar_panel(
            rows,
            lambda r: None if r["median_cost_ratio"] is None else 100 * (r["median_cost_ratio"] - 1),
            "median cost above the grid reference (%)",
            ".1f",
            size,
        ),
        _bar_panel(rows, lambda r: r["median_intrusion_m"], "median path length in group zones (m)", ".2f", size),
    ]
    width = size[0] * len(panels)
    header = np.full((70, width, 3), 255, np.uint8)
    cv2.putText(header, title, (20, 28), _FONT, 0.65, _TEXT, 2, cv2.LINE_AA)
    for j, social in enumerate((False, True)):
        x = 20 + 240 * j
        cv2.rectangle(header, (x, 44), (x + 16, 58), _BAR_COLOURS[social], -1)
        label = "with the social layer" if social else "without the social layer"
        cv2.putText(header, label, (x + 24, 56), _FONT, 0.45, _TEXT, 1, cv2.LINE_AA)
    return np.vstack([header, np.hstack(panels)])
