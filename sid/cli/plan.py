"""``sid plan SCENARIO --out DIR``: plan the scenario's robot task on its costmap; write path.json and plan.png."""

from __future__ import annotations

import argparse
import sys

from costmap.mapfile import MapFileError
from planner.facade import DEFAULT_PLANNER, PLANNERS, resolve_planner
from planner.problem import DEFAULT_COST_WEIGHT, PlanningError
from sid.experiments.harness import goal_zone_warning
from sid.experiments.scenario_plan import plan_scenario, write_plan
from sid.scenario.loader import ScenarioError, load_scenario


def add_planning_options(parser: argparse.ArgumentParser, time_default: float) -> None:
    """The planner options ``sid plan``, ``sid demo`` and ``sid compare`` share."""
    parser.add_argument(
        "--time", type=float, default=time_default, metavar="S", help=f"planner time budget in seconds ({time_default})"
    )
    parser.add_argument("--seed", type=int, default=None, metavar="N", help="random seed (positive) for OMPL")
    parser.add_argument(
        "--iterations",
        type=int,
        default=None,
        metavar="K",
        help="cap on the planner's iterations; with --seed, a run that stops on the cap repeats exactly",
    )
    parser.add_argument(
        "--cost-weight",
        type=float,
        default=DEFAULT_COST_WEIGHT,
        metavar="W",
        help=f"w in cost = integral of (1 + w c/252) ds ({DEFAULT_COST_WEIGHT:g}; 0 = shortest path)",
    )


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "plan",
        help="plan a scenario's robot task on its costmap (OMPL or grid planner); write path.json and plan.png",
        description=__doc__.replace("``", ""),
    )
    parser.add_argument("scenario", help="scenario file (.json or .yaml); see docs/scenario.md")
    parser.add_argument("--out", required=True, help="output folder (created if missing)")
    parser.add_argument(
        "--planner", default=DEFAULT_PLANNER, help=f"one of {', '.join(PLANNERS)} (default {DEFAULT_PLANNER})"
    )
    parser.add_argument(
        "--no-social", action="store_true", help="plan without the social layer (the 'without recognition' robot)"
    )
    add_planning_options(parser, time_default=0.5)
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    try:
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
    except (ScenarioError, MapFileError, PlanningError, ValueError) as exc:
        print(f"sid plan: {exc}", file=sys.stderr)
        return 2
    warning = goal_zone_warning(comparison.task)
    if warning:
        print(f"sid plan: warning: {warning}", file=sys.stderr)
    files = write_plan(comparison, args.out)
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
    if r.seed is not None:
        print(f"repeat exactly: --seed {r.seed} --iterations {r.iterations} --time {max(10.0, 4 * args.time):g}")
    for path in files.values():
        print(f"wrote {path}")
    return 0 if r.success else 1
