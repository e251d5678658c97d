"""``sid compare SCENARIO... [--planners ...] [--runs K]``: every planner x with/without the social layer x K seeds;
prints a table (median time, success, cost ratio to the grid reference, o-space intrusion) and draws a chart."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import cv2

from costmap.mapfile import MapFileError
from planner.facade import PLANNERS
from planner.problem import DEFAULT_COST_WEIGHT, PlanningError
from sid.experiments.compare import format_summary, run_matrix, summarise, summary_chart
from sid.scenario.loader import ScenarioError, load_scenario


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "compare",
        help="compare the planners on scenarios, with and without the social layer (table and chart)",
        description=__doc__.replace("``", ""),
    )
    parser.add_argument("scenarios", nargs="+", metavar="SCENARIO", help="scenario files (.json or .yaml)")
    parser.add_argument("--planners", nargs="+", default=list(PLANNERS), help=f"default: {' '.join(PLANNERS)}")
    parser.add_argument("--runs", type=int, default=3, metavar="K", help="seeds 1..K per planner (default 3)")
    parser.add_argument("--time", type=float, default=0.5, metavar="S", help="time budget per run in s (0.5)")
    parser.add_argument(
        "--cost-weight", type=float, default=DEFAULT_COST_WEIGHT, metavar="W", help="w of the cost (see sid plan)"
    )
    parser.add_argument("--out", default="sid-compare", help="output folder for summary.json and planners.png")
    parser.set_defaults(func=run)


def _progress_bar(done: int, total: int, what: str) -> None:
    filled = int(30 * done / max(total, 1))
    line = f"\r[{'#' * filled}{'.' * (30 - filled)}] {done}/{total} {what}"
    print(f"{line[:118]:<118}", end="\n" if done == total else "", file=sys.stderr, flush=True)


def run(args: argparse.Namespace) -> int:
    try:
        scenarios = [load_scenario(path) for path in args.scenarios]
        runs = run_matrix(
            scenarios, args.planners, args.runs, (args.time,), cost_weight=args.cost_weight, progress=_progress_bar
        )
    except (ScenarioError, MapFileError, PlanningError, ValueError) as exc:
        print(f"\nsid compare: {exc}", file=sys.stderr)
        return 2
    rows = summarise(runs)
    print(format_summary(rows))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "summary.json").write_text(json.dumps(rows, indent=2, allow_nan=False) + "\n")
    title = f"Planner comparison: {len(scenarios)} scenario(s), {args.runs} seeds, {args.time:g} s budget (medians)"
    if not cv2.imwrite(str(out / "planners.png"), summary_chart(summarise(runs, by_scenario=False), title)):
        print(f"sid compare: could not write {out / 'planners.png'}", file=sys.stderr)
        return 2
    print(f"wrote {out / 'summary.json'}\nwrote {out / 'planners.png'}")
    return 0
