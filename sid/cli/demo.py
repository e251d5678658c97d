"""``sid demo [--out DIR]``: the main result on a built-in scenario: plan past a conversation without and with
group recognition; write comparison.png, metrics.json and the scenario file."""

from __future__ import annotations

import argparse

from sid.cli.common import (
    ExitCode,
    add_output_option,
    check_output_folder,
    fail,
    plain_text,
    print_written,
    staged_output,
)
from sid.cli.planning import INPUT_ERRORS, add_planner_option, add_planning_options, warn_zones
from sid.experiments.demo import DEMO_ITERATIONS, DEMO_SEED, run_demo
from sid.experiments.plan_pictures import format_table
from sid.scenario.loader import load_scenario

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "demo",
        help="the main result: plan past a conversation without and with group recognition (no input needed)",
        description=plain_text(__doc__),
    )
    add_output_option(parser, "demo", "comparison.png, metrics.json and scenario.json")
    parser.add_argument("--scenario", default=None, help="a scenario file to use instead of the built-in one")
    add_planner_option(parser)
    add_planning_options(parser, time_default=5.0, seed=DEMO_SEED, iterations=DEMO_ITERATIONS)
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    try:
        check_output_folder(args.out)
        scenario = load_scenario(args.scenario) if args.scenario else None
        with staged_output(args.out, ("scenario.json",)) as staged:  # scenario.json: only for the built-in one
            comparison = run_demo(
                staged.path,
                scenario,
                planner=args.planner,
                time_limit=args.time,
                seed=args.seed,
                max_iterations=args.iterations,
                cost_weight=args.cost_weight,
                progress=lambda line: print(line, flush=True),
            )
    except (*INPUT_ERRORS, OSError) as exc:
        return fail("sid demo", exc)
    warn_zones("sid demo", comparison.task.scenario, comparison.task.groups)
    print()
    print(format_table(comparison))
    print()
    names = ("comparison.png", "metrics.json") + (() if args.scenario else ("scenario.json",))
    print_written(staged.folder / name for name in names)
    return ExitCode.OK if all(run.result.success for run in comparison.runs.values()) else ExitCode.NO_PATH
