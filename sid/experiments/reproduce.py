"""The reproduction reports (``sid reproduce table1|navigation``) and the helpers they share: markdown tables, number
cells, strict JSON."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import cv2

from sid.documents import plural
from sid.experiments.charts import NAVIGATION_PANELS, bar_chart
from sid.experiments.demo import comparison_picture
from sid.experiments.harness import summarise
from sid.experiments.navigation import NAV_LAYOUTS, NavigationResult
from sid.experiments.table1 import METRICS, PAPER_TABLE1, UNITS, Table1Result, table1_json
from sid.synthetic.layouts import LAYOUTS, VARIATIONS

__all__ = [
    "cell",
    "json_ready",
    "markdown_table",
    "navigation_json",
    "navigation_markdown",
    "percent",
    "table1_markdown",
    "write_json",
    "write_navigation_report",
    "write_table1_report",
]


def cell(value: float | None, spec: str = ".3f", unit: str = "") -> str:
    """A table cell: ``value`` formatted with ``spec`` (and a unit), or "-" when it is missing or not finite."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return format(value, spec) + unit


def percent(value: float | None) -> str:
    return "-" if value is None else f"{100 * value:.0f} %"


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A GitHub-flavoured markdown table (header row, separator, rows)."""
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def json_ready(value: Any) -> Any:
    """``value`` with non-finite floats replaced by None (strict JSON has no NaN), tuples as lists, numpy scalars
    as Python numbers."""
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_ready(v) for v in value]
    if hasattr(value, "item") and callable(value.item):  # numpy scalar
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json(path: Path, data: Any) -> None:
    path.write_text(json.dumps(json_ready(data), indent=2, allow_nan=False) + "\n")


# --- navigation --------------------------------------------------------------------------------------------------


def navigation_markdown(result: NavigationResult, seeds: int, command: str) -> str:
    """``navigation.md``: settings, the per-planner table, the per-layout table and the tasks that failed."""
    settings = result.settings
    by_planner = summarise(result.runs, ("planner",))
    by_layout = summarise(result.runs, ("layout",))
    budget = f"{settings.time_limit:g} s per plan" + (
        f", capped at {settings.max_iterations} iterations" if settings.max_iterations else ""
    )
    lines = [
        "# Navigation with and without group recognition",
        "",
        f"Command: `{command}`",
        "",
        f"{plural(result.tasks, 'task')} ({plural(len({r['layout'] for r in result.runs}), 'layout')} x "
        f"{plural(seeds, 'draw')} x 2 directions; "
        "see `sid.experiments.navigation` and docs/reproduction.md), planners: "
        f"{', '.join(settings.planners)}; budget {budget}; cost weight {settings.cost_weight:g}. "
        "Each task is planned on the costmap without the social layer (known map + LiDAR) and on the costmap with "
        "it (with), "
        "same planner, budget and seed; both paths are measured against the groups detected from the task's people.",
        "",
        "## Per planner",
        "",
        markdown_table(
            [
                "planner",
                "costmap",
                "runs",
                "success",
                "intrusion rate",
                "mean intrusion",
                "crosses group",
                "min dist (median / worst)",
                "length / straight",
                "detour (with / without)",
                "planning (median)",
            ],
            [
                [
                    row["planner"],
                    "with" if row["social_layer"] else "without",
                    str(row["runs"]),
                    percent(row["success_rate"]),
                    percent(row["intrusion_rate"]),
                    cell(row["mean_intrusion_m"], ".2f", " m"),
                    percent(row["crossing_rate"]),
                    f"{cell(row['median_min_person_distance_m'], '.2f')} / "
                    f"{cell(row['worst_min_person_distance_m'], '.2f')} m",
                    cell(row["median_length_ratio"], ".3f"),
                    cell(row["median_detour"], ".3f"),
                    cell(row["median_planning_time_s"], ".2f", " s"),
                ]
                for row in by_planner
            ],
        ),  # fmt: skip
        "",
        "## Per layout (all planners together)",
        "",
        markdown_table(
            [
                "layout",
                "people",
                "intrusion rate without / with",
                "crosses group without / with",
                "min dist (median) without / with",
            ],
            [_layout_row(name, by_layout) for name in dict.fromkeys(r["layout"] for r in result.runs)],
        ),  # fmt: skip
        "",
        "Intrusion rate: share of successful paths that enter a group's interaction zone (the polygon the social "
        "layer paints, `costmap.layers.social.group_zone_polygon`); mean intrusion: length inside zones averaged over "
        "successful paths; crosses group: the path crosses the segment between two members; min dist: to the "
        "nearest person's centre; detour: path length with the social layer over the same planner's length without "
        "it on the same task. Planning times depend on this machine and its load.",
    ]
    whole = {r["task"] for r in result.runs if r["group_detected_whole"]}
    planned = {r["task"] for r in result.runs}
    lines += [
        "",
        "The group detector (`sid.perception.groups.detect_groups`, exact positions) found the whole conversation "
        f"as one group in {len(whole)} of {len(planned)} planned tasks"
        + ("." if len(whole) == len(planned) else f"; not in: {', '.join(sorted(planned - whole))}."),
    ]
    if result.impossible:
        lines += ["", "## Tasks that could not be planned", ""]
        lines += [f"- {name}: {reason}" for name, reason in result.impossible.items()]
    return "\n".join(lines) + "\n"


def _layout_row(name: str, rows: list[dict]) -> list[str]:
    without = next((r for r in rows if r["layout"] == name and not r["social_layer"]), {})
    with_ = next((r for r in rows if r["layout"] == name and r["social_layer"]), {})

    def pair(key: str, show: Callable[[float | None], str]) -> str:
        return f"{show(without.get(key))} / {show(with_.get(key))}"

    return [
        f"{name}: {NAV_LAYOUTS[name].description}",
        str(NAV_LAYOUTS[name].size),
        pair("intrusion_rate", percent),
        pair("crossing_rate", percent),
        pair("median_min_person_distance_m", lambda v: cell(v, ".2f", " m")),
    ]


def navigation_json(result: NavigationResult, seeds: int) -> dict[str, Any]:
    """``navigation.json``: settings, layouts, the summaries by planner and by layout, failed tasks, every run."""
    settings = result.settings
    return {
        "settings": {
            "planners": list(settings.planners),
            "time_limit_s": settings.time_limit,
            "max_iterations": settings.max_iterations,
            "cost_weight": settings.cost_weight,
            "seeds": seeds,
            "tasks": result.tasks,
        },
        "layouts": {
            name: {
                "description": spec.description,
                "people": spec.size,
                "angles_deg": spec.angles_deg,
                "radius_m": spec.radius,
            }
            for name, spec in NAV_LAYOUTS.items()
            if any(r["layout"] == name for r in result.runs)
        },  # fmt: skip
        "summary": summarise(result.runs, ("planner",)),
        "by_layout": summarise(result.runs, ("layout",)),
        "impossible": result.impossible,
        "runs": result.runs,
    }


def write_navigation_report(result: NavigationResult, out_dir: str | Path, seeds: int, command: str) -> dict[str, Path]:
    """Write ``navigation.md``, ``navigation.json``, ``navigation.png`` (the chart) and, when a comparison was kept,
    ``navigation_example.png`` (the demo's picture of the task where recognition avoided the most intrusion)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {name: out / f"navigation.{name}" for name in ("md", "json", "png")}
    paths["md"].write_text(navigation_markdown(result, seeds, command))
    write_json(paths["json"], navigation_json(result, seeds))
    s = result.settings
    budget = f"{s.time_limit:g} s budget" + (f", {s.max_iterations} iterations cap" if s.max_iterations else "")
    bar_chart(
        summarise(result.runs, ("planner",)),
        NAVIGATION_PANELS,
        paths["png"],
        "Navigation past conversations: without vs with the social layer",
        f"{plural(result.tasks, 'task')} (group sizes 2-5, both directions, {plural(seeds, 'draw')} per layout), "
        f"{budget}",
    )
    if result.example is not None:
        paths["example"] = out / "navigation_example.png"
        if not cv2.imwrite(str(paths["example"]), comparison_picture(result.example)):
            raise OSError(f"could not write {paths['example']}")
    return paths


# --- table 1 -----------------------------------------------------------------------------------------------------

_FORMATS = {"IZA": ".3f", "IPX": ".3f", "IPY": ".3f", "HPX": ".3f", "HPY": ".3f", "HFD": ".2f"}


def table1_markdown(result: Table1Result, command: str) -> str:
    """``table1.md``: ours next to the paper's RMSEs, then detection counts and biases, then the settings."""
    s = result.settings
    dn, kn = s.depth_noise, s.keypoint_noise
    rows = []
    for name, ours in result.scenarios.items():
        rows.append([f"**{name}** ours", *[cell(ours[m], _FORMATS[m]) for m in METRICS]])
        rows.append([f"{name} paper", *[cell(PAPER_TABLE1[name][m], _FORMATS[m]) for m in METRICS]])
    detection = []
    for name, ours in result.scenarios.items():
        people, group, bias = ours["people"], ours["group"], ours["bias"]
        detection.append(
            [
                name,
                str(ours["frames"]),
                f"{percent(people['detection_rate'])} ({people['matched']}/{people['truth']})",
                str(people["false_detections"]),
                str(people["without_facing"]),
                f"{percent(group['detection_rate'])} ({group['found']}/{group['frames']})",
                f"{percent(group['exact_rate'])}",
                str(group["not_found"]),
                " / ".join(cell(bias[m], "+.3f") for m in ("HPX", "HPY")) + " m",
                cell(bias["HFD"], "+.1f", " deg"),
                " / ".join(cell(bias[m], "+.3f") for m in ("IPX", "IPY")) + " m",
            ]
        )
    lines = [
        "# Table 1 on synthetic data: ours vs the paper",
        "",
        f"Command: `{command}`",
        "",
        f"RMSE per scenario over {plural(s.variations, 'layout variation')} x {plural(s.frames, 'frame')}, "
        f"seed {s.seed}. "
        "IZA: interaction-zone area (m^2); IPX/IPY: interest point (m); HPX/HPY: person position (m); HFD: facing "
        "direction (deg). Group errors over the frames where the group was found, person errors over matched "
        "people (HFD: those with a facing); misses are counted in the second table.",
        "",
        markdown_table(["scenario", *[f"{m} ({UNITS[m]})" for m in METRICS]], rows),
        "",
        "## Detection and bias",
        "",
        markdown_table(
            [
                "scenario",
                "frames",
                "people found",
                "false people",
                "no facing",
                "group found",
                "exact members",
                "frames without group",
                "bias HPX / HPY",
                "bias HFD",
                "bias IPX / IPY",
            ],
            detection,
        ),  # fmt: skip
        "",
        "## Settings",
        "",
        f"- depth noise (Intel D400 RMS model z^2 * subpixel / (f * B), f = 420 px, B = 50 mm): subpixel "
        f"{dn.subpixel:g} px -> {100 * dn.rms(2.0, 420.0) / 2.0:.2f} % of the distance at 2 m "
        f"(datasheet bound: <= 2 %); correlation {dn.correlation_px:g} px; random holes {dn.hole_fraction:g}; "
        f"edge holes {dn.edge_holes:g} within {dn.edge_width_px} px of jumps > {dn.edge_jump_m:g} m; stereo shadow "
        f"{'on' if dn.stereo_shadow else 'off'}; depth unit {1000 * dn.depth_unit_m:g} mm",
        f"- keypoint noise: {kn.sigma_px:g} px Gaussian per axis (colour 1280x720), {100 * kn.drop:g} % dropped",
        f"- person match radius {s.match_radius:g} m (Hungarian on ground-plane distance)",
        "- variations: " + "; ".join(_variation_text(v) for v in VARIATIONS[: s.variations]),
        "- ground truth: exact (rendered scene), the group's interest point and area as the detector defines them "
        "on exact data; the paper's came from manual annotation. See docs/reproduction.md.",
    ]
    return "\n".join(lines) + "\n"


def _variation_text(variation: dict) -> str:
    if not variation:
        return "as described"
    parts = []
    for key, value in variation.items():
        if key == "turn":
            turns = ", ".join(f"{n} {value * spec.turn_deg:+g}" for n, spec in LAYOUTS.items())
            parts.append(f"turned about the centre (deg: {turns})")
        elif key == "distance_offset":
            parts.append(f"{value:+g} m distance")
        elif key == "jitter_xy":
            parts.append(f"{100 * value:g} cm jitter")
        elif key == "jitter_theta":
            parts.append(f"{math.degrees(value):g} deg facing jitter")
        elif key == "seed":
            parts.append(f"seed {value}")
    return ", ".join(parts)


def write_table1_report(result: Table1Result, out_dir: str | Path, command: str) -> dict[str, Path]:
    """Write ``table1.md`` and ``table1.json`` into ``out_dir`` (created if missing)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {"md": out / "table1.md", "json": out / "table1.json"}
    paths["md"].write_text(table1_markdown(result, command))
    write_json(paths["json"], table1_json(result))
    return paths
