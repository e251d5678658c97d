"""``sid eval crowd DIR...``: the people tracker and the group tracker on real pedestrian trajectories.

Each DIR is a trajectory set (``obsmat.txt`` + ``groups.txt``, ETH/UCY format: ``sid.experiments.trajectories``),
replayed as a robot's perception would feed it (seeded 0.1 m noise, 10 % misses, optionally a camera's rate and
field of view) and scored against the true identities and walking groups, beside the coherent-motion reference
(``sid.experiments.crowd``; docs/tracking.md). A table per set; ``--json`` for everything.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from sid.cli.common import fail, name_width, plain_text, positive_int, whole_number
from sid.distribution import MissingDependencyError
from sid.errors import InputError
from sid.experiments.crowd import DEFAULT_GRID, CrowdSettings, cross_validate, evaluate_crowd
from sid.experiments.trajectories import ReplaySettings, TrajectoryError, TrajectorySet, load_trajectory_set
from sid.tracking.view import ViewCone

__all__ = ["FOV_DEGREES", "add_crowd_parser", "run_crowd"]

FOV_DEGREES = 87.0
"""The RealSense D435i colour camera's horizontal opening (degrees), the default ``--fov``."""


def add_crowd_parser(tasks: argparse._SubParsersAction) -> None:
    """``sid eval crowd``: the replay's options and the output format."""
    defaults = ReplaySettings()
    parser = tasks.add_parser(
        "crowd",
        help="people and walking-group tracking on real pedestrian trajectories (MOTA, IDF1, G-MITRE, group F1)",
        description=plain_text((__doc__ or "").split("\n\n", 1)[1].strip())
        + " Takes a few seconds per set; progress on stderr.",
    )
    parser.add_argument("folders", nargs="+", metavar="DIR", help="trajectory sets (obsmat.txt + groups.txt each)")
    parser.add_argument(
        "--rate", type=float, default=None, metavar="HZ",
        help="detections per second, interpolated between annotations (default: at the annotation times, 2.5 Hz)",
    )  # fmt: skip
    parser.add_argument(
        "--interval", type=float, default=None, metavar="S",
        help="seconds between annotation steps (default: read from the annotated positions and velocities; 0.4 s "
        "in the ETH and UCY sets)",
    )  # fmt: skip
    parser.add_argument(
        "--noise", type=float, default=defaults.noise, metavar="M",
        help=f"standard deviation of the position noise per axis (default {defaults.noise} m)",
    )  # fmt: skip
    parser.add_argument(
        "--miss-rate", type=float, default=defaults.miss_rate, metavar="P",
        help=f"share of detections dropped (default {defaults.miss_rate})",
    )  # fmt: skip
    parser.add_argument(
        "--seed", type=whole_number(0), default=defaults.seed, help=f"seed of noise and misses ({defaults.seed})"
    )
    parser.add_argument(
        "--view", type=_view_pose, default=None, metavar="X,Y,YAW",
        help="a robot standing at (X, Y) m in each set's frame, looking along YAW degrees: only the people in its "
        "field of view are detected and scored (default: everyone, the scene camera's area); "
        "a negative X: --view=-2,0,0",
    )  # fmt: skip
    parser.add_argument("--fov", type=float, default=FOV_DEGREES, metavar="DEG", help="--view's opening (87)")
    parser.add_argument("--range", type=float, default=6.0, metavar="M", help="--view's range (6 m)")
    parser.add_argument(
        "--cross-validate", action="store_true",
        help="leave one set out over the trackers' grid (sid.experiments.crowd.DEFAULT_GRID; about 20 minutes in one "
        "process)",
    )  # fmt: skip
    parser.add_argument(
        "--workers", type=positive_int, default=None, metavar="N",
        help="with --cross-validate: score the grid points in N worker processes (default 1; the same result)",
    )  # fmt: skip
    out = parser.add_mutually_exclusive_group()
    out.add_argument("--json", action="store_true", help="print JSON (every score, the settings) instead of a table")
    out.add_argument("--table", action="store_true", help="print the table (the default)")
    parser.set_defaults(func=run_crowd)


def run_crowd(args: argparse.Namespace) -> int:
    from sid.experiments.progress import ProgressBar

    try:
        if args.workers is not None and not args.cross_validate:
            raise InputError("--workers spreads the cross-validation's grid points: give --cross-validate too")
        view = None
        if args.view is not None:
            x, y, yaw = args.view
            view = ViewCone(x, y, math.radians(yaw), math.radians(args.fov), max_range=args.range)
        replay = ReplaySettings(rate=args.rate, noise=args.noise, miss_rate=args.miss_rate, seed=args.seed, view=view)
        sets = _load(args.folders, args.interval)
        settings = CrowdSettings(replay=replay)
        if args.cross_validate:
            result = cross_validate(sets, settings, DEFAULT_GRID, ProgressBar("cross-validation"), args.workers or 1)
        else:
            result = evaluate_crowd(sets, settings, ProgressBar("crowd"))
    except (ValueError, MissingDependencyError) as exc:  # TrajectoryError and bad settings are ValueErrors
        return fail("sid eval crowd", exc)
    except OSError as exc:
        print(f"sid eval crowd: cannot read {exc.filename}: {exc.strerror}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        print(_folds_table(result) if args.cross_validate else _table(result))
    return 0


def _load(folders: list[str], interval: float | None) -> list[TrajectorySet]:
    sets = [load_trajectory_set(folder, interval) for folder in folders]
    names = [s.name for s in sets]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise TrajectoryError(f"two sets are named {twice[0]!r} (the folder's name names a set): rename one")
    for s in sets:
        for note in s.notes:
            print(f"sid eval crowd: {s.name}: {note}", file=sys.stderr)
    return sets


def _view_pose(text: str) -> tuple[float, float, float]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise argparse.ArgumentTypeError(f"expected X,Y,YAW (metres, metres, degrees), got {text!r}")
    return values[0], values[1], values[2]


def _table(result: dict[str, Any]) -> str:
    w = name_width(result["sets"], 12)
    lines = [
        f"{'set':<{w}} {'frames':>6} {'MOTA':>6} {'IDF1':>6} {'IDsw':>5} {'/100':>5} | "
        f"{'G-MITRE P':>9} {'R':>5} {'F1':>5} {'T=2/3 F1':>8} {'T=1 F1':>6} | "
        f"{'coherent G-MITRE F1':>19} {'T=2/3 F1':>8}"
    ]
    for name, s in result["sets"].items():
        people, ours, ref = s["people"], s["groups"], s["coherent_motion"]
        lines.append(
            f"{name:<{w}} {s['frames']:>6} {people['mota']:>6.3f} {people['idf1']:>6.3f} {people['id_switches']:>5} "
            f"{people['id_switches_per_100_tracks']:>5.1f} | {ours['gmitre']['precision']:>9.3f} "
            f"{ours['gmitre']['recall']:>5.3f} {ours['gmitre']['f1']:>5.3f} {ours['groups_T2/3']['f1']:>8.3f} "
            f"{ours['groups_T1']['f1']:>6.3f} | {ref['gmitre']['f1']:>19.3f} {ref['groups_T2/3']['f1']:>8.3f}"
        )
    return "\n".join(lines)


def _folds_table(result: dict[str, Any]) -> str:
    w = name_width((fold["held_out"] for fold in result["folds"]), 12)
    lines = [f"{'held out':<{w}} {'stage':<9} {'train':>6} {'held out':>8}  chosen"]
    for fold in result["folds"]:
        for stage, score in (("tracker", "idf1"), ("groups", "f1"), ("coherent", "f1"), ("reporting", "idf1")):
            entry = fold[stage]
            chosen = ", ".join(f"{k}={v:g}" for k, v in entry["chosen"].items())
            metric = "IDF1" if score == "idf1" else "G-MITRE F1"
            lines.append(
                f"{fold['held_out']:<{w}} {stage:<9} {entry[f'train_{score}']:>6.3f} "
                f"{entry[f'held_out_{score}']:>8.3f}  {chosen} ({metric})"
            )
    return "\n".join(lines)
