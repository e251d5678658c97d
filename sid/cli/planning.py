"""The scenario and planner options of the commands that plan (``sid plan``, ``sid demo``, ``sid costmap``,
``sid compare``, ``sid simulate``), and what they report as bad input."""

from __future__ import annotations

import argparse
import sys

from costmap.mapfile import MapFileError
from planner.facade import DEFAULT_PLANNER, DEFAULT_SOFT_LIMIT_S, MAX_SEED, PLANNERS
from planner.problem import DEFAULT_COST_WEIGHT, PlanningError
from sid.experiments.harness import Comparison, goal_zone_warning
from sid.scenario.loader import ScenarioError

__all__ = [
    "INPUT_ERRORS",
    "add_planner_option",
    "add_planning_options",
    "add_scenario_arguments",
    "seed_number",
    "warn_goal_zone",
]

INPUT_ERRORS = (ScenarioError, MapFileError, PlanningError, ValueError)
"""What a command that loads a scenario and plans on it reports as bad input (exit code 2), not as a crash."""


def add_scenario_arguments(parser: argparse.ArgumentParser, no_social_help: str) -> None:
    """The scenario file, the output folder and ``--no-social`` (``sid costmap``, ``sid plan``)."""
    parser.add_argument("scenario", help="scenario file (.json or .yaml); see docs/scenario.md")
    parser.add_argument("--out", required=True, help="output folder (created if missing)")
    parser.add_argument("--no-social", action="store_true", help=no_social_help)


def add_planner_option(parser: argparse.ArgumentParser) -> None:
    """``--planner NAME`` (``sid plan``, ``sid demo``)."""
    parser.add_argument(
        "--planner", default=DEFAULT_PLANNER, help=f"one of {', '.join(PLANNERS)} (default {DEFAULT_PLANNER})"
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


def add_planning_options(parser: argparse.ArgumentParser, time_default: float) -> None:
    """The planner budget options ``sid plan`` and ``sid demo`` share."""
    parser.add_argument(
        "--time",
        type=float,
        default=time_default,
        metavar="S",
        help=f"planner time budget in seconds ({time_default}); without --iterations BIT* stops earlier once it has a "
        f"path, when its cost settles or after {DEFAULT_SOFT_LIMIT_S} s",
    )
    parser.add_argument(
        "--seed", type=seed_number, default=None, metavar="N", help=f"random seed for OMPL, 1 to {MAX_SEED}"
    )
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


def warn_goal_zone(command: str, comparison: Comparison) -> None:
    """Warn on stderr when the task's goal lies inside a group zone (the plan is still made and reported)."""
    warning = goal_zone_warning(comparison.task)
    if warning:
        print(f"{command}: warning: {warning}", file=sys.stderr)
