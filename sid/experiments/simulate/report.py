"""The sweep's report (``sid simulate --sweep``): a markdown table, the JSON of every run and the summaries, and a
chart like ``sid reproduce navigation``'s (``sid.experiments.charts``)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from sid.documents import plural
from sid.experiments.charts import Panel, bar_chart, from_key
from sid.experiments.reproduce import cell, markdown_table, percent, write_json
from sid.experiments.simulate.sweep import sweep_summary

__all__ = ["HEADER", "SIMULATE_PANELS", "sweep_markdown", "write_sweep_report"]

SIMULATE_PANELS = (
    Panel("success rate (goal, no collision)", from_key("success_rate")),
    Panel("o-space intrusion rate (share of runs entering a zone)", from_key("intrusion_rate")),
    Panel("mean o-space intrusion length (m)", from_key("mean_intrusion_m")),
    Panel("median min distance to a person (m)", from_key("median_min_person_distance_m")),
    Panel("median time to goal (s)", from_key("median_time_to_goal_s"), ".1f"),
    Panel("collision rate", from_key("collision_rate")),
)


def _rows(summary: Sequence[dict], key: str) -> list[list[str]]:
    return [
        [
            str(row[key]),
            "with" if row["social_layer"] else "without",
            str(row["runs"]),
            percent(row["success_rate"]),
            percent(row["collision_rate"]),
            percent(row["intrusion_rate"]),
            cell(row["mean_intrusion_m"], ".2f", " m"),
            percent(row["crossing_rate"]),
            f"{cell(row['median_min_person_distance_m'], '.2f')} / {cell(row['worst_min_person_distance_m'], '.2f')} m",
            cell(row["median_time_to_goal_s"], ".1f", " s"),
        ]
        for row in summary
    ]


HEADER = [
    "costmap",
    "runs",
    "success",
    "collisions",
    "intrusion rate",
    "mean intrusion",
    "crosses group",
    "min dist (median / worst)",
    "time to goal (median)",
]


def sweep_markdown(records: Sequence[dict], command: str, wall_time_s: float, executor: str) -> str:
    """``simulate.md``: the table over all scenes, then per scene."""
    overall = sweep_summary([r | {"all": "all"} for r in records], ("all",))
    lines = [
        "# Closed-loop navigation with and without the social layer",
        "",
        f"Command: `{command}`",
        "",
        f"{plural(len(records), 'run')} ({executor}, wall time {wall_time_s:.0f} s). Each run drives the robot from "
        "its start with the camera and LiDAR in the loop (`sid.experiments.simulate`); metrics are measured on the "
        "driven trajectory against the people and groups where they truly were at each step.",
        "",
        "## All scenes",
        "",
        markdown_table(["scenes", *HEADER], _rows(overall, "all")),
        "",
        "## Per scene",
        "",
        markdown_table(["scene", *HEADER], _rows(sweep_summary(records, ("scene",)), "scene")),
        "",
        "Success: goal reached without collision within the time limit. Intrusion rate: share of successful runs "
        "whose trajectory entered a group's interaction zone; mean intrusion: length inside zones over successful "
        "runs; min dist: to the nearest person's centre over the run (successful runs).",
    ]
    failed = [r for r in records if not r["success"]]
    if failed:
        lines += ["", "## Runs that did not reach the goal", ""]
        lines += [
            f"- {r['scene']} {'with' if r['social_layer'] else 'without'} seed {r['seed']}: {r['reason']}"
            for r in failed
        ]
    return "\n".join(lines) + "\n"


def write_sweep_report(
    records: Sequence[dict], out_dir: str | Path, command: str, wall_time_s: float, executor: str
) -> dict[str, Path]:
    """Write ``simulate.md``, ``simulate.json`` (summaries and every run) and ``simulate.png`` (the chart)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {name: out / f"simulate.{name}" for name in ("md", "json", "png")}
    paths["md"].write_text(sweep_markdown(records, command, wall_time_s, executor))
    by_scene = sweep_summary(records, ("scene",))
    write_json(
        paths["json"],
        {"command": command, "executor": executor, "wall_time_s": wall_time_s, "summary": by_scene, "runs": records},
    )
    # bar_chart puts one pair of bars per row["planner"]: here, one pair per scene.
    bar_chart(
        [row | {"planner": row["scene"]} for row in by_scene],
        SIMULATE_PANELS,
        paths["png"],
        "Closed-loop navigation past conversations: without vs with the social layer",
        f"{plural(len(records), 'run')} over {plural(len({r['scene'] for r in records}), 'scene')}, camera and LiDAR "
        "in the loop",
    )
    return paths
