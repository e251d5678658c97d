"""The scenario and planner options of the commands that plan (``sid plan``, ``sid demo``, ``sid costmap``,
``sid compare``, ``sid simulate``), and what they report as bad input."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence

from costmap.mapfile import MapFileError
from planner.facade import DEFAULT_PLANNER, DEFAULT_SOFT_LIMIT_S, MAX_SEED, PLANNERS
from planner.problem import DEFAULT_COST_WEIGHT, MAX_COST_WEIGHT, PlanningError
from sid.cli.common import add_output_option, positive_int, positive_seconds
from sid.experiments.harness import zone_warnings
from sid.perception.group import Group
from sid.scenario.loader import Scenario, ScenarioError

__all__ = [
    "INPUT_ERRORS",
    "add_planner_option",
    "add_planning_options",
    "add_scenario_arguments",
    "seed_number",
    "warn_zones",
]

INPUT_ERRORS = (ScenarioError, MapFileError, PlanningError, ValueError)
"""What a command that loads a scenario and plans on it reports as bad input (exit code 2; NoPathError, a task without
a solution: 3), not as a crash."""


def add_scenario_arguments(parser: argparse.ArgumentParser, command: str, writes: str, no_social_help: str) -> None:
    """The scenario file, the output folder (for ``writes``) and ``--no-social`` (``sid costmap``, ``sid plan``)."""
    parser.add_argument("scenario", help="scenario file (.json or .yaml); see docs/scenario.md")
    add_output_option(parser, command, writes)
    parser.add_argument("--no-social", action="store_true", help=no_social_help)


def add_planner_option(parser: argparse.ArgumentParser, default: str = DEFAULT_PLANNER) -> None:
    """``--planner NAME`` (``sid plan``, ``sid demo``, ``sid simulate``)."""
    parser.add_argument(
        "--planner", default=default, metavar="NAME", help=f"one of {', '.join(PLANNERS)} (default: %(default)s)"
    )


def seed_number(text: str) -> int:
    """argparse type of ``--seed``: a whole number from 1 to ``MAX_SEED`` (what OMPL takes)."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if not 1 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"expected a whole number from 1 to {MAX_SEED}, got {text!r}")
    return value


def add_planning_options(
    parser: argparse.ArgumentParser, time_default: float, seed: int | None = None, iterations: int | None = None
) -> None:
    """The planner budget options ``sid plan`` and ``sid demo`` share, with the command's defaults (None: no seed,
    from the clock; no cap on iterations)."""
    parser.add_argument(
        "--time",
        type=positive_seconds,
        default=time_default,
        metavar="S",
        help="planner time budget in seconds (default: %(default)s); without --iterations BIT* stops earlier once it "
        f"has a path, when its cost settles or after {DEFAULT_SOFT_LIMIT_S} s",
    )
    parser.add_argument(
        "--seed",
        type=seed_number,
        default=seed,
        metavar="N",
        help=f"random seed for OMPL, 1 to {MAX_SEED} (default: {'%(default)s' if seed is not None else 'random'})",
    )
    parser.add_argument(
        "--iterations",
        type=positive_int,
        default=iterations,
        metavar="K",
        help="cap on the planner's iterations; with --seed, a run that stops on the cap repeats exactly (default: "
        f"{'%(default)s' if iterations is not None else 'none'})",
    )
    parser.add_argument(
        "--cost-weight",
        type=_cost_weight,
        default=DEFAULT_COST_WEIGHT,
        metavar="W",
        help="w in cost = integral of (1 + w c/252) ds (default: %(default)s; 0 = shortest path)",
    )


def _cost_weight(text: str) -> float:
    """argparse type of ``--cost-weight``: a number in [0, MAX_COST_WEIGHT], refused before anything is printed."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 <= value <= MAX_COST_WEIGHT:  # NaN too
        raise argparse.ArgumentTypeError(f"expected a number from 0 to {MAX_COST_WEIGHT:g}, got {text!r}")
    return value


def warn_zones(command: str, scenario: Scenario, groups: Sequence[Group]) -> None:
    """Warn on stderr when the scenario's start or goal lies inside the zone of one of ``groups`` (the task is
    still planned, or run, and reported)."""
    for warning in zone_warnings(scenario, groups):
        print(f"{command}: warning: {warning}", file=sys.stderr)
