"""``sid compare SCENARIO... [--planners ...] [--runs K]``: every planner x with/without the social layer x K seeds;
prints a table (median time, success, cost ratio to the grid reference, o-space intrusion) and draws a chart."""

from __future__ import annotations

import argparse

from planner.facade import PLANNERS
from planner.problem import DEFAULT_COST_WEIGHT
from sid.cli.common import (
    add_output_option,
    check_output_folder,
    fail,
    plain_text,
    positive_seconds,
    print_written,
    staged_output,
)
from sid.cli.planning import INPUT_ERRORS
from sid.documents import plural
from sid.experiments.compare import BY_SCENARIO, format_summary, write_comparison
from sid.experiments.harness import prepare, run_matrix, summarise
from sid.experiments.progress import ProgressBar
from sid.scenario.loader import load_scenario

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "compare",
        help="compare the planners on scenarios, with and without the social layer (table and chart)",
        description=plain_text(__doc__),
    )
    parser.add_argument("scenarios", nargs="+", metavar="SCENARIO", help="scenario files (.json or .yaml)")
    parser.add_argument("--planners", nargs="+", default=list(PLANNERS), help=f"default: {' '.join(PLANNERS)}")
    parser.add_argument(
        "--runs", type=int, default=3, metavar="K", help="seeds 1..K per planner (default: %(default)s)"
    )
    parser.add_argument(
        "--time", type=positive_seconds, default=0.5, metavar="S",
        help="time budget per run in s (default: %(default)s)",
    )  # fmt: skip
    parser.add_argument(
        "--cost-weight", type=float, default=DEFAULT_COST_WEIGHT, metavar="W", help="w of the cost (see sid plan)"
    )
    add_output_option(parser, "compare", "summary.json and planners.png")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    try:
        check_output_folder(args.out)  # before the runs, not after them
    except ValueError as exc:
        return fail("sid compare", exc)
    bar = ProgressBar("compare")
    try:
        tasks = [prepare(load_scenario(path), args.cost_weight) for path in args.scenarios]
        runs = run_matrix(tasks, args.planners, args.runs, (args.time,), progress=bar)
    except INPUT_ERRORS as exc:
        bar.close()
        return fail("sid compare", exc)
    print(format_summary(summarise([run.record() for run in runs], BY_SCENARIO)))
    title = f"Planner comparison: {plural(len(tasks), 'scenario')}, {plural(args.runs, 'seed')}, {args.time:g} s budget"
    try:
        with staged_output(args.out, ()) as staged:
            paths = {key: staged.final(path) for key, path in write_comparison(runs, staged.path, title).items()}
    except OSError as exc:
        return fail("sid compare", exc)
    print_written(paths.values())
    return 0
