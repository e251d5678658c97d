"""``bench.json`` / ``bench.md``: the machine, the settings, one record per stage; and comparing two reports.

``bench.json`` (format ``sid-bench/1``; keep it stable so successive runs compare)::

    {"format": "sid-bench/1",
     "machine": {"cpu", "logical_cores", "physical_cores", "usable_cores", "load_average", "platform", "python",
                 "numpy", "scipy", "scikit-learn", "shapely", "opencv-python-headless", "onnxruntime", "ompl",
                 "pyrealsense2", "onnxruntime_providers", "commit", "date"},
     "settings": {"quick", "only", "warmup", "min_runs", "max_runs", "budget_s", "plan_runs", "pose_threads",
                  "pose_provider"},
     "stages": {NAME: {"median_ms", "min_ms", "max_ms", "runs", ...optional extras}},
     "notes": [...], "failures": {NAME: message}}

Optional stage extras: ``paper_ms`` (the paper's Jetson figure for that step), ``ratio`` and ``ratio_to`` (median /
the median of stage ``ratio_to``), ``cost_ratio`` (planning), and counts that show the stage did its work.
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path
from typing import Any

from sid.cpu import physical_cores, usable_cpus
from sid.documents import is_number, load_document, plural, summary
from sid.errors import InputError

__all__ = [
    "COMPARED_SETTINGS",
    "FIXED_FIELDS",
    "IDENTITY_EXTRAS",
    "FORMAT",
    "LIBRARIES",
    "PAPER_COLUMN",
    "build_report",
    "format_comparison",
    "load_report",
    "machine_info",
    "markdown",
    "write_report",
]

FORMAT = "sid-bench/1"
LIBRARIES = ("numpy", "scipy", "scikit-learn", "shapely", "opencv-python-headless", "onnxruntime", "ompl",
             "pyrealsense2")  # fmt: skip
FIXED_FIELDS = ("median_ms", "min_ms", "max_ms", "runs")
PAPER_COLUMN = "paper (Jetson Orin NX, another machine) ms"
# A change beyond these ratios is flagged by ``format_comparison``: timings on a shared machine move by about that
# much between runs (docs/benchmarks.md, "Measuring a change side by side").
SLOWER, FASTER = 1.10, 1 / 1.10
# Settings and stage extras that change what a stage times: ``format_comparison`` warns when they differ.
COMPARED_SETTINGS = ("quick", "pose_provider", "pose_threads", "plan_runs")
IDENTITY_EXTRAS = ("pose", "provider", "threads", "image")


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _commit(repo: Path) -> str | None:
    try:
        head = subprocess.run(["git", "-C", str(repo), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, timeout=5, check=True).stdout.strip()  # fmt: skip
        dirty = subprocess.run(["git", "-C", str(repo), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=5, check=True).stdout.strip()  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return None
    return head + ("-dirty" if dirty else "")


def machine_info(repo: Path) -> dict[str, Any]:
    """Where the numbers come from: CPU, cores, load, Python and library versions, commit and date (UTC)."""
    info: dict[str, Any] = {
        "cpu": _cpu_model(),
        "logical_cores": os.cpu_count(),
        "physical_cores": physical_cores(range(os.cpu_count() or 1)),
        "usable_cores": len(usable_cpus()),
        "load_average": [round(v, 2) for v in os.getloadavg()] if hasattr(os, "getloadavg") else None,
        "platform": platform.platform(),
        "python": platform.python_version(),
    }
    for name in LIBRARIES:
        try:
            info[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            info[name] = None
    try:
        import onnxruntime

        info["onnxruntime_providers"] = onnxruntime.get_available_providers()
    except ImportError:
        info["onnxruntime_providers"] = None
    info["commit"] = _commit(repo)
    info["date"] = datetime.now(timezone.utc).isoformat(timespec="seconds")
    return info


def build_report(
    machine: dict[str, Any],
    settings: dict[str, Any],
    stages: dict[str, dict[str, Any]],
    notes: list[str],
    failures: dict[str, str],
) -> dict[str, Any]:
    return {"format": FORMAT, "machine": machine, "settings": settings, "stages": stages, "notes": notes,
            "failures": failures}  # fmt: skip


def load_report(path: str | Path) -> dict[str, Any]:
    """Read a ``bench.json``; ValueError naming the file and the problem when it is not one."""
    path = Path(path)
    try:
        data = load_document(path, "bench report")
    except ValueError as exc:  # names the file: unreadable, or not valid JSON
        raise InputError(f"bench: {exc}") from None
    stages = data.get("stages") if isinstance(data, dict) else None
    if not isinstance(stages, dict):
        raise InputError(f'bench: {path} is not a sid bench report (no "stages" object)')
    for key in ("machine", "settings"):  # read by the comparison, after the whole run
        if key in data and not isinstance(data[key], dict):
            raise InputError(f'bench: {path}: "{key}" must be an object, got {summary(data[key])}')
    for name, stage in stages.items():
        median = stage.get("median_ms") if isinstance(stage, dict) else None
        if not is_number(median) or median <= 0:  # a ratio against 0, NaN or inf means nothing
            raise InputError(f'bench: {path}: stage {name!r} has no positive "median_ms", got {median!r}')
    return data


def _details(stage: dict[str, Any]) -> str:
    parts = []
    if "ratio" in stage:
        parts.append(f"{stage['ratio']:.2f} x {stage['ratio_to']}")
    for key, value in stage.items():
        if key in FIXED_FIELDS or key in ("paper_ms", "ratio", "ratio_to"):
            continue
        if isinstance(value, float):
            value = f"{value:.3g}"
        elif isinstance(value, list):
            value = "x".join(str(v) for v in value)
        parts.append(f"{key} {value}")
    return ", ".join(str(p) for p in parts)


def _ms(value: float) -> str:
    return f"{value:.3f}" if value < 100 else f"{value:.1f}"


def markdown(report: dict[str, Any], comparison: str | None = None) -> str:
    """The report as a markdown page: machine, settings, the stage table with the paper column, notes."""
    m, s = report["machine"], report["settings"]
    libraries = ", ".join(f"{name} {m.get(name)}" for name in LIBRARIES if m.get(name))
    lines = [
        "# sid bench",
        "",
        f"- machine: {m['cpu']}, {m['logical_cores']} logical cores ({m.get('physical_cores')} physical, "
        f"{m.get('usable_cores')} usable), load average at start {m.get('load_average')}",
        f"- software: Python {m['python']} on {m['platform']}; {libraries}",
        f"- commit {m.get('commit')}, {m['date']}",
        f"- settings: {'--quick' if s['quick'] else 'full run'}"
        + (f", --only {s['only']}" if s.get("only") else "")
        + f"; per stage {s['warmup']} warm-up calls, then {s['min_runs']}-{s['max_runs']} timed calls within "
        f"{s['budget_s']} s; {plural(s['plan_runs'], 'seed')} per sampling planner",
        "",
        "Times in milliseconds per call: median, minimum and maximum over the timed runs. The paper column is the "
        "paper's Table 2 on a Jetson Orin NX (another machine, GPU pose model); it is shown where a stage does the "
        "same step. See docs/benchmarks.md for what each stage measures.",
        "",
        f"| stage | median ms | min ms | max ms | runs | {PAPER_COLUMN} | details |",
        "|---|---:|---:|---:|---:|---:|---|",
    ]
    for name, stage in report["stages"].items():
        paper = stage.get("paper_ms")
        lines.append(
            f"| {name} | {_ms(stage['median_ms'])} | {_ms(stage['min_ms'])} | {_ms(stage['max_ms'])} | "
            f"{stage['runs']} | {'' if paper is None else paper} | {_details(stage)} |"
        )
    if report.get("notes"):
        lines += ["", "## Notes", ""] + [f"- {note}" for note in report["notes"]]
    if comparison:
        lines += ["", "## Change against the earlier report", "", "```", comparison, "```"]
    return "\n".join(lines) + "\n"


def write_report(report: dict[str, Any], out_dir: str | Path, comparison: str | None = None) -> tuple[Path, Path]:
    """Write ``bench.json`` and ``bench.md`` into ``out_dir`` (created if missing); returns their paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    json_path, md_path = out / "bench.json", out / "bench.md"
    json_path.write_text(json.dumps(report, indent=2) + "\n")
    md_path.write_text(markdown(report, comparison))
    return json_path, md_path


def format_comparison(old: dict[str, Any], new: dict[str, Any]) -> str:
    """Per stage present in both: old and new median (ms), new / old (flagged beyond +-10 %), and old and new
    minimum (ms); then the stages found in only one of them (counted, not listed, for old stages left out by
    ``--only``), and warnings: run settings that differ (``COMPARED_SETTINGS``, where both reports record them),
    stages whose identity extras differ (``IDENTITY_EXTRAS``: the same name timed other work), and different CPUs."""
    old_stages, new_stages = old["stages"], new["stages"]
    common = [name for name in new_stages if name in old_stages]
    rows = [("stage", "old median", "new median", "new/old", "old min", "new min", "")]
    for name in common:
        before, after = old_stages[name], new_stages[name]
        ratio = after["median_ms"] / before["median_ms"] if before["median_ms"] > 0 else float("inf")
        flag = "slower" if ratio > SLOWER else "faster" if ratio < FASTER else ""
        rows.append((name, _ms(before["median_ms"]), _ms(after["median_ms"]), f"{ratio:.2f}", _min_ms(before),
                     _min_ms(after), flag))  # fmt: skip
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = ["  ".join(c.ljust(w) if i == 0 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths, strict=True)))
             .rstrip() for r in rows]  # fmt: skip
    only_old = [n for n in old_stages if n not in new_stages]
    only_new = [n for n in new_stages if n not in old_stages]
    if only_old and new.get("settings", {}).get("only"):
        lines.append(f"{plural(len(only_old), 'stage')} of the old report not selected by --only")
    elif only_old:
        lines.append("only in the old report: " + ", ".join(only_old))
    if only_new:
        lines.append("only in the new report: " + ", ".join(only_new))
    old_settings, new_settings = old.get("settings") or {}, new.get("settings") or {}
    changed = [f"{key} {old_settings[key]!r} -> {new_settings[key]!r}" for key in COMPARED_SETTINGS
               if key in old_settings and key in new_settings and old_settings[key] != new_settings[key]]  # fmt: skip
    if changed:
        lines.append("warning: different run settings (" + "; ".join(changed) + "); ratios mix settings and code")
    for name in common:
        extras = [f"{key} {old_stages[name].get(key)!r} -> {new_stages[name].get(key)!r}" for key in IDENTITY_EXTRAS
                  if old_stages[name].get(key) != new_stages[name].get(key)]  # fmt: skip
        if extras:
            lines.append(f"warning: {name} timed other work (" + "; ".join(extras) + ")")
    old_cpu, new_cpu = old.get("machine", {}).get("cpu"), new.get("machine", {}).get("cpu")
    if old_cpu != new_cpu:
        lines.append(f"warning: different machines (old: {old_cpu}, new: {new_cpu}); ratios mix machine and code")
    if not common:
        lines.append("no stage in common")
    return "\n".join(lines)


def _min_ms(stage: dict[str, Any]) -> str:
    """A stage's minimum for the comparison table; "-" when the report has none."""
    value = stage.get("min_ms")
    return _ms(value) if is_number(value) else "-"
