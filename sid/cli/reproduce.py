"""``sid reproduce table1|navigation``: reproduce the paper's accuracy table on synthetic scenes, and the
navigation study with and without group recognition. Settings and how to read the outputs: docs/reproduction.md."""

from __future__ import annotations

import argparse
import shlex
import sys
from dataclasses import dataclass

from planner.facade import PLANNERS
from planner.problem import DEFAULT_COST_WEIGHT
from sid.cli.common import (
    ExitCode,
    add_output_option,
    check_output_folder,
    fail,
    plain_text,
    print_written,
    staged_output,
    whole_number,
)
from sid.experiments.navigation import NAV_LAYOUTS, NavSettings, navigation_tasks, run_navigation
from sid.experiments.progress import ProgressBar
from sid.synthetic.layouts import LAYOUTS, VARIATIONS
from sid.synthetic.noise import DepthNoise, KeypointNoise

__all__ = [
    "NAVIGATION_DEFAULTS",
    "NavigationDefaults",
    "QUICK_NAVIGATION",
    "QUICK_TABLE1",
    "TABLE1_DEFAULTS",
    "add_parser",
    "navigation_command",
    "table1_command",
]

TABLE1_DEFAULTS = {"frames": 50, "variations": len(VARIATIONS)}
QUICK_TABLE1 = {"frames": 2, "variations": 1}


@dataclass(frozen=True)
class NavigationDefaults:
    """What ``sid reproduce navigation`` runs when an option is not given: layouts, draws, planners, budget (s)."""

    layouts: tuple[str, ...]
    seeds: int
    planners: tuple[str, ...]
    time: float


NAVIGATION_DEFAULTS = NavigationDefaults(tuple(NAV_LAYOUTS), 2, PLANNERS, 0.5)
QUICK_NAVIGATION = NavigationDefaults(("P2", "T3"), 1, ("grid", "rrtconnect"), 0.2)


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "reproduce",
        help="reproduce the paper: Table 1 accuracy on synthetic S1-S5, and the navigation with/without study",
        description=plain_text(__doc__),
    )
    studies = parser.add_subparsers(dest="study", required=True, metavar="STUDY")
    _add_table1(studies)
    _add_navigation(studies)


def _add_study(studies: argparse._SubParsersAction, name: str, help: str, description: str) -> argparse.ArgumentParser:
    """A study's parser, with the option every study has (``--out``)."""
    parser = studies.add_parser(name, help=help, description=description)
    add_output_option(parser, "reproduce", f"the {name} report")
    return parser


def _add_table1(studies: argparse._SubParsersAction) -> None:
    depth, kp = DepthNoise(), KeypointNoise()
    p = _add_study(
        studies,
        "table1",
        "RMSE of zone area, interest point, positions and facing on S1-S5 vs the paper (table1.md/.json)",
        "Render S1-S5 (and their documented variations) with D435-like depth noise, keypoint noise and occlusion, run "
        "the full pipeline, and compare the errors with the paper's Table 1.",
    )
    p.add_argument("--frames", type=int, default=None, metavar="N", help="frames per layout variation (50)")
    p.add_argument(
        "--variations", type=int, default=None, metavar="K",
        help=f"first K of the {len(VARIATIONS)} documented variations per layout (all)",
    )  # fmt: skip
    p.add_argument("--seed", type=whole_number(0), default=0, metavar="S", help="noise seed (0)")
    p.add_argument("--scenarios", nargs="+", default=list(LAYOUTS), metavar="SN", help="layouts (S1 .. S5)")
    noise = p.add_argument_group("noise (defaults: a D435i on textured clothes, a good pose model)")
    noise_options = (  # flag, default, metavar, help with {:g} for the default
        ("--subpixel", depth.subpixel, "PX", "disparity RMS error in px ({:g}: Intel's figure for textured surfaces, "
         "0.76 %% of the distance at 2 m; 0.21 reaches the datasheet's 2 %% bound)"),
        ("--correlation", depth.correlation_px, "PX", "spatial correlation length of the depth noise in px ({:g})"),
        ("--holes", depth.hole_fraction, "P", "fraction of depth pixels missing at random ({:g})"),
        ("--edge-holes", depth.edge_holes, "P", "probability that a pixel next to a depth jump is missing ({:g})"),
        ("--keypoint-sigma", kp.sigma_px, "PX", "keypoint pixel noise per axis, colour pixels ({:g})"),
        ("--keypoint-drop", kp.drop, "P", "probability that a visible keypoint is missed ({:g})"),
    )  # fmt: skip
    for flag, default, metavar, text in noise_options:
        noise.add_argument(flag, type=float, default=default, metavar=metavar, help=text.format(default))
    noise.add_argument(
        "--exact", action="store_true",
        help="no depth or keypoint noise at all (occlusion stays): isolates the pipeline's systematic errors",
    )  # fmt: skip
    p.add_argument(
        "--quick", action="store_true",
        help=f"a smoke run; defaults become {QUICK_TABLE1['variations']} variation x {QUICK_TABLE1['frames']} frames",
    )  # fmt: skip
    p.set_defaults(func=table1_command)


def _add_navigation(studies: argparse._SubParsersAction) -> None:
    p = _add_study(
        studies,
        "navigation",
        "plan past conversations with and without the social layer, per planner (navigation.md/.json/.png)",
        "The demo's with/without comparison over a family of tasks: group sizes 2-5 (S1-S5, a wide pair, a triangle, "
        "a circle and a semicircle of five), random turns and offsets, both directions.",
    )
    p.add_argument("--planners", nargs="+", default=None, metavar="P", help=f"default: {' '.join(PLANNERS)}")
    p.add_argument("--seeds", type=int, default=None, metavar="K", help="draws per layout (2); each in both directions")
    p.add_argument("--layouts", nargs="+", default=None, metavar="L", help=f"default: {' '.join(NAV_LAYOUTS)}")
    p.add_argument(
        "--time",
        type=float,
        default=None,
        metavar="S",
        help="planner time budget per plan in s (0.5); without --iterations BIT* stops earlier once it has a path",
    )
    p.add_argument(
        "--iterations", type=int, default=None, metavar="K",
        help="cap on planner iterations; runs that stop on the cap repeat exactly",
    )  # fmt: skip
    p.add_argument(
        "--cost-weight", type=float, default=DEFAULT_COST_WEIGHT, metavar="W", help="w of the cost (see sid plan)"
    )
    p.add_argument(
        "--quick", action="store_true",
        help=f"a smoke run; defaults become: layouts {' '.join(QUICK_NAVIGATION.layouts)}, 1 draw, planners "
        f"{' '.join(QUICK_NAVIGATION.planners)}, {QUICK_NAVIGATION.time} s",
    )  # fmt: skip
    p.set_defaults(func=navigation_command)


def _command() -> str:
    return "sid " + " ".join(shlex.quote(a) for a in sys.argv[1:]) if sys.argv[1:] else "sid reproduce"


def table1_command(args: argparse.Namespace) -> int:
    # Imported here, not at the top: the pipeline and its lifting load only when a study runs.
    from sid.experiments.reproduce import table1_markdown, write_table1_report
    from sid.experiments.table1 import Table1Settings, run_table1

    defaults = QUICK_TABLE1 if args.quick else TABLE1_DEFAULTS
    frames = args.frames if args.frames is not None else defaults["frames"]
    variations = args.variations if args.variations is not None else defaults["variations"]
    try:
        if args.exact:
            depth, keypoints = DepthNoise.exact(), KeypointNoise(0.0, 0.0)
        else:
            depth = DepthNoise(
                subpixel=args.subpixel,
                correlation_px=args.correlation,
                hole_fraction=args.holes,
                edge_holes=args.edge_holes,
            )
            keypoints = KeypointNoise(args.keypoint_sigma, args.keypoint_drop)
        settings = Table1Settings(
            scenarios=tuple(s.upper() for s in args.scenarios),
            frames=frames,
            variations=variations,
            seed=args.seed,
            depth_noise=depth,
            keypoint_noise=keypoints,
        )
        check_output_folder(args.out)  # fail before the run, not after it
        result = run_table1(settings, progress=ProgressBar("table1"))
        with staged_output(args.out, ()) as staged:
            paths = {
                key: staged.final(path) for key, path in write_table1_report(result, staged.path, _command()).items()
            }
    except (ValueError, OSError) as exc:
        return fail("sid reproduce", exc)
    print(table1_markdown(result, _command()))
    print_written(paths.values())
    return 0


def navigation_command(args: argparse.Namespace) -> int:
    from sid.experiments.reproduce import navigation_markdown, write_navigation_report

    defaults = QUICK_NAVIGATION if args.quick else NAVIGATION_DEFAULTS
    layouts = [name.upper() for name in args.layouts] if args.layouts else defaults.layouts
    seeds = args.seeds if args.seeds is not None else defaults.seeds
    planners = args.planners or defaults.planners
    time_limit = args.time if args.time is not None else defaults.time
    try:
        settings = NavSettings(tuple(planners), time_limit, args.iterations, args.cost_weight)
        tasks = navigation_tasks(seeds, layouts)
        check_output_folder(args.out)
        result = run_navigation(tasks, settings, progress=ProgressBar("navigation"))
        with staged_output(args.out, ("navigation_example.png",)) as staged:  # written only when a task has one
            written = write_navigation_report(result, staged.path, seeds, _command())
            paths = {key: staged.final(path) for key, path in written.items()}
    except (ValueError, OSError) as exc:
        return fail("sid reproduce", exc)
    print(navigation_markdown(result, seeds, _command()))
    print_written(paths.values())
    return ExitCode.OK if not result.impossible else ExitCode.NO_PATH
