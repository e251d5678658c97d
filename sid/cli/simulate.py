"""``sid simulate SCENE [--out DIR]``: drive a simulated robot with its camera and LiDAR in the loop past people,
with or without the social layer; ``--sweep SCENE... --seeds K`` runs many and summarises them. See
docs/simulate.md."""

from __future__ import annotations

import argparse
import shlex
import sys
import time
from pathlib import Path

from sid.cli.common import (
    ExitCode,
    add_output_option,
    check_output_folder,
    fail,
    plain_text,
    positive_number,
    print_written,
    staged_output,
)
from sid.cli.planning import INPUT_ERRORS, add_planner_option, warn_zones
from sid.distribution import MissingDependencyError
from sid.documents import plural, special_file
from sid.errors import InputError
from sid.experiments.progress import ProgressBar
from sid.experiments.simulate.loop import PERCEPTIONS, RunOptions
from sid.experiments.simulate.scenes import SCENE_ORDER, load_scene, scene_list
from sid.scenario.sight import scenario_groups

__all__ = ["RUN_FILES", "SUMMARY_KEYS", "SWEEP_FILES", "add_parser", "run"]

RUN_FILES = ("run.json", "run.mp4", "run.gif", "run.png")
"""The files one run writes into --out (run.gif with --gif, run.png with --still): an earlier run's are replaced or
removed."""
SWEEP_FILES = ("simulate.md", "simulate.json", "simulate.png")
"""The files a sweep writes into --out."""

SUMMARY_KEYS = (
    "success",
    "reason",
    "collisions",
    "time_to_goal_s",
    "path_length_m",
    "min_person_distance_m",
    "ospace_intrusion_m",
    "crosses_group",
    "replans",
)


_SEEDS = 5
"""Seeds per scene and mode of a sweep without ``--seeds``."""
_SINGLE_RUN_OPTIONS = (("scene", "SCENE"), ("seed", "--seed"), ("gif", "--gif"), ("still", "--still"))
"""The options a sweep would ignore (attribute, as written): its scenes follow --sweep, its seeds are 1..K."""
_SWEEP_OPTIONS = ("seeds", "workers", "ray")
"""The options only a sweep reads."""


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value < 2**31:
        raise argparse.ArgumentTypeError(f"expected a whole number from 0 to {2**31 - 1}, got {text!r}")
    return value


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "simulate",
        help="drive a simulated robot past people with perception in the loop, with or without the social layer",
        description=plain_text(__doc__),
    )
    parser.add_argument("scene", nargs="?", help=f"a built-in scene ({', '.join(SCENE_ORDER)}) or a scenario file")
    add_output_option(parser, "simulate", "run.json and run.mp4 (sweeps: simulate.md/.json/.png)")
    parser.add_argument("--no-social", action="store_true", help="the robot without recognition (LiDAR + inflation)")
    add_planner_option(parser, default=RunOptions.planner)
    parser.add_argument(
        "--seed", type=_seed, default=None, metavar="N",
        help="0: the scene as written (default); N >= 1: people jittered by 5 cm / 5 deg, and the sensor noise, from N",
    )  # fmt: skip
    parser.add_argument("--model", default=None, metavar="M.onnx", help="a pose model instead of TruthPose")
    parser.add_argument(
        "--perception", choices=PERCEPTIONS, default="camera",
        help="camera: rendered frames through the real pipeline and trackers (default); exact: true poses and "
        "velocities of the people in view",
    )  # fmt: skip
    parser.add_argument("--unknown-map", action="store_true", help="no known map: the LiDAR discovers obstacles too")
    parser.add_argument("--gif", action="store_true", help="also write run.gif (every other frame)")
    parser.add_argument(
        "--still",
        type=positive_number("number of seconds", zero=True),  # NaN picked the first step without a word
        default=None,
        metavar="T",
        help="also write run.png, the picture at T seconds",
    )
    parser.add_argument("--list", action="store_true", help="list the built-in scenes and exit")
    sweep = parser.add_argument_group("sweeps")
    sweep.add_argument("--sweep", nargs="+", default=None, metavar="SCENE", help="scenes (or 'all') to sweep")
    sweep.add_argument("--seeds", type=int, default=None, metavar="K", help=f"seeds per scene and mode ({_SEEDS})")
    sweep.add_argument("--workers", type=int, default=None, metavar="N", help="parallel worker processes (1)")
    sweep.add_argument(
        "--ray", default=None, metavar="ADDRESS",
        help="run on a Ray cluster ('local' starts one here, 'auto' joins a running head); needs sid-social[cluster]",
    )  # fmt: skip
    parser.set_defaults(func=run)


def _options(args: argparse.Namespace) -> RunOptions:
    return RunOptions(
        social=not args.no_social,
        planner=args.planner,
        seed=args.seed or 0,
        model=None if args.model is None else Path(args.model),
        perception=args.perception,
        unknown_map=args.unknown_map,
    )


def run(args: argparse.Namespace) -> int:
    if args.list:
        for name, description in scene_list():
            print(f"{name:10s} {description}")
        return 0
    problem = _option_of_the_other_mode(args)
    if problem:
        return fail("sid simulate", ValueError(problem))
    if args.sweep:
        return _sweep(args)
    if args.scene is None:
        return fail("sid simulate", ValueError("give a scene (see --list), or --sweep SCENE..."))
    from sid.experiments.simulate.run import write_run

    try:
        options = _options(args)
        if args.model is not None:
            if not Path(args.model).is_file():
                raise InputError(f"--model {args.model}: {special_file(args.model) or 'no such file'}")
            from sid.perception.pose.session import quiet_load_warnings

            quiet_load_warnings()
        out = check_output_folder(args.out)
        world = load_scene(args.scene)
        scenario = world.scenario
        warn_zones("sid simulate", scenario, scenario_groups(scenario))
        with staged_output(out, RUN_FILES) as staged:  # whole files only, even when interrupted; earlier ones go
            record = write_run(
                world, options, staged.path, gif=args.gif, progress=ProgressBar("simulate"), still_s=args.still
            )
    except (*INPUT_ERRORS, OSError) as exc:
        return fail("sid simulate", exc)
    for key in SUMMARY_KEYS:
        value = record[key]
        print(f"{key:22s} {round(value, 3) if isinstance(value, float) else value}")
    extra = (("run.gif",) if args.gif else ()) + (("run.png",) if args.still is not None else ())
    print_written(out / name for name in ("run.json", "run.mp4", *extra))
    return ExitCode.OK if record["success"] else ExitCode.NO_PATH


def _option_of_the_other_mode(args: argparse.Namespace) -> str | None:
    """What is wrong when an option of one run is given with ``--sweep``, or one of a sweep without it (either
    would be ignored in silence), or None."""
    if args.sweep:
        for name, written in _SINGLE_RUN_OPTIONS:
            value = getattr(args, name)
            if value is not None and value is not False:
                return (
                    f"{written}: applies to one run, not to a --sweep (its scenes follow --sweep, its seeds are "
                    "1..--seeds, and it writes no pictures of a run)"
                )
        return None
    for name in _SWEEP_OPTIONS:
        if getattr(args, name) is not None:
            return f"--{name}: applies to a --sweep only; one run takes a SCENE (and --seed N)"
    return None


def _sweep(args: argparse.Namespace) -> int:
    from sid.experiments.simulate.report import sweep_markdown, write_sweep_report
    from sid.experiments.simulate.sweep import run_sweep, sweep_jobs

    scenes = list(SCENE_ORDER) if args.sweep == ["all"] else args.sweep
    command = "sid " + " ".join(shlex.quote(a) for a in sys.argv[1:]) if sys.argv[1:] else "sid simulate"
    try:
        options = _options(args)
        check_output_folder(args.out)
        jobs = sweep_jobs(scenes, _SEEDS if args.seeds is None else args.seeds, options)
        workers = 1 if args.workers is None else args.workers
        executor = f"Ray at {args.ray}" if args.ray else plural(workers, "worker process", "worker processes")
        start = time.perf_counter()
        records = run_sweep(jobs, workers, args.ray, ProgressBar("sweep"))
        wall = time.perf_counter() - start
        print(sweep_markdown(records, command, wall, executor))
        with staged_output(args.out, SWEEP_FILES) as staged:
            written = write_sweep_report(records, staged.path, command, wall, executor).values()
        print_written(staged.final(path) for path in written)
    except (*INPUT_ERRORS, OSError, MissingDependencyError) as exc:
        return fail("sid simulate", exc)
    return 0
