"""``sid plan SCENARIO [--out DIR]``: plan the scenario's robot task on its costmap; write path.json and plan.png."""

from __future__ import annotations

import argparse
import sys

from planner.facade import resolve_planner
from sid.cli.common import ExitCode, check_output_folder, fail, plain_text, print_written, staged_output
from sid.cli.planning import (
    INPUT_ERRORS,
    add_planner_option,
    add_planning_options,
    add_scenario_arguments,
    warn_zones,
)
from sid.experiments.path_metrics import crosses_group
from sid.experiments.scenario_plan import plan_scenario, write_plan
from sid.scenario.loader import load_scenario

__all__ = ["add_parser", "run"]


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "plan",
        help="plan a scenario's robot task on its costmap (OMPL or grid planner); write path.json and plan.png",
        description=plain_text(__doc__),
    )
    add_scenario_arguments(
        parser, "plan", "path.json and plan.png", "plan without the social layer (the 'without recognition' robot)"
    )
    add_planner_option(parser)
    add_planning_options(parser, time_default=0.5)
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    try:
        check_output_folder(args.out)  # before the plan, not after it
        name = resolve_planner(args.planner)
        scenario = load_scenario(args.scenario)
        budget = "deterministic" if name == "grid" else f"{args.time:g} s budget"
        print(f"planning {scenario.name} with {name} ({budget}) ...", flush=True)
        comparison = plan_scenario(
            scenario,
            social=not args.no_social,
            planner=name,
            time_limit=args.time,
            seed=args.seed,
            max_iterations=args.iterations,
            cost_weight=args.cost_weight,
        )
    except INPUT_ERRORS as exc:
        return fail("sid plan", exc)
    warn_zones("sid plan", comparison.task.scenario, comparison.task.groups)
    try:
        with staged_output(args.out, ()) as staged:
            files = {key: staged.final(path) for key, path in write_plan(comparison, staged.path).items()}
    except OSError as exc:
        return fail("sid plan", exc)
    (run,) = comparison.runs.values()
    r, m = run.result, run.metrics
    print(r.message)
    if r.success:
        closest = "-" if m["min_person_distance_m"] is None else f"{m['min_person_distance_m']:.2f} m"
        print(
            f"length {m['path_length_m']:.2f} m, in group zones {m['ospace_intrusion_m']:.2f} m, "
            f"crosses a group: {'yes' if m['crosses_group'] else 'no'}, closest person {closest}, "
            f"planning {m['planning_time_s']:.2f} s"
        )
        crossed = [g for g in comparison.task.groups if crosses_group(r.path, comparison.task.scenario.people, [g])]
        if crossed and not args.no_social:
            names = ", ".join(f"({', '.join(map(str, g.members))})" for g in crossed)
            print(
                f"sid plan: note: the path passes between members of group {names}: no way round was cheaper (the "
                "social layer is a cost, not a wall; a corridor it fills leaves no other way)",
                file=sys.stderr,
            )
    if r.seed is not None and r.iterations > 0:  # no iteration ran within --time: nothing to repeat
        print(f"repeat exactly: --seed {r.seed} --iterations {r.iterations} --time {max(10.0, 4 * args.time):g}")
    print_written(files.values())
    return ExitCode.OK if r.success else ExitCode.NO_PATH
