"""``sid bench [--out DIR] [--quick] [--compare OLD.json] [--only PATTERN]``: time the stages side by side in one
run and write DIR/bench.json and DIR/bench.md (see docs/benchmarks.md)."""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict
from pathlib import Path

from sid.experiments.bench import (
    FULL,
    QUICK,
    Context,
    benchmarks,
    format_comparison,
    load_report,
    machine_info,
    markdown,
    run_suite,
    select,
    write_report,
)
from sid.experiments.bench.report import build_report

REPO_ROOT = Path(__file__).resolve().parents[2]
PLAN_RUNS_FULL, PLAN_RUNS_QUICK = 5, 1


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "bench",
        help="time grouping, alignment, lifting, pose models, the per-frame pipeline, costmap and planners",
        description=__doc__.replace("``", ""),
    )
    parser.add_argument(
        "--out", default="out/bench", help="output folder for bench.json and bench.md (default %(default)s)"
    )
    parser.add_argument(
        "--quick", action="store_true", help="few repeats (~0.15 s per stage, 1 planner seed): a smoke run"
    )
    parser.add_argument("--compare", metavar="OLD.json", help="an earlier bench.json: print the change per stage")
    parser.add_argument(
        "--only",
        metavar="PATTERN",
        help="comma-separated stage names or globs, e.g. 'group,align/*' ('group' means group/...); "
        "the stages a ratio refers to run too",
    )
    parser.add_argument("--list", action="store_true", help="list the benchmarks and exit")
    parser.add_argument(
        "--shared",
        type=Path,
        default=REPO_ROOT.parent / "shared",
        help="folder with models/ and data/ (default: ../shared next to the repository)",
    )
    parser.set_defaults(func=run)


def _progress(index: int, total: int, name: str, status: str) -> None:
    if status:
        print(f"[{index + 1:>2}/{total}] {name}: {status}", file=sys.stderr, flush=True)
    else:
        print(f"[{index + 1:>2}/{total}] {name} ...", file=sys.stderr, flush=True)


def run(args: argparse.Namespace) -> int:
    try:
        old = load_report(args.compare) if args.compare else None
    except ValueError as exc:
        print(f"sid bench: {exc}", file=sys.stderr)
        return 2
    settings = QUICK if args.quick else FULL
    ctx = Context(settings, args.shared, PLAN_RUNS_QUICK if args.quick else PLAN_RUNS_FULL)
    items = benchmarks(ctx)
    if args.list:
        for item in items:
            print(f"{item.name:<28} {item.what}")
        return 0
    try:
        chosen = select(items, args.only)
    except ValueError as exc:
        print(f"sid bench: {exc}", file=sys.stderr)
        return 2
    machine = machine_info(REPO_ROOT)  # before the run: the load average is the one the run started under
    result = run_suite(chosen, ctx, _progress)
    run_settings = {"quick": args.quick, "only": args.only, "plan_runs": ctx.plan_runs} | asdict(settings)
    report = build_report(machine, run_settings, result.stages, ctx.notes, result.failures)
    comparison = format_comparison(old, report) if old is not None else None
    json_path, md_path = write_report(report, args.out, comparison)
    print(markdown(report, comparison), end="")
    print(f"wrote {json_path} and {md_path}", file=sys.stderr)
    if result.failures:
        print(f"sid bench: {len(result.failures)} benchmark(s) failed: {', '.join(result.failures)}", file=sys.stderr)
        return 1
    return 0
