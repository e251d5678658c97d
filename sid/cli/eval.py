"""``sid eval fformation DIR...``: score the group detector on F-formation benchmark datasets."""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from pathlib import Path

from sid.cli.groups import add_group_params, group_params_from
from sid.experiments.fformation import (
    DEFAULT_THRESHOLDS,
    LIKELY_METRES_M,
    LabelledFrame,
    load_dataset,
    median_neighbour_distance,
    parse_threshold,
)
from sid.experiments.fformation import evaluate as evaluate_fformation


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("eval", help="score the detectors on benchmark datasets")
    tasks = parser.add_subparsers(dest="task", required=True, metavar="TASK")
    ff = tasks.add_parser(
        "fformation",
        help="group detection on F-formation datasets (features.mat + groundtruth.mat)",
        description=(
            "Runs the group detector on each DIR (a folder with features.mat and groundtruth.mat, or with "
            "sequence sub-folders that have them, pooled frame by frame) and prints mean precision, mean recall "
            "and F1 per dataset and pooled, at each tolerance T (a truth group is found when a detected group "
            "shares at least T of the larger of the two)."
        ),
    )
    ff.add_argument("dirs", nargs="+", metavar="DIR", help="dataset folder (e.g. ../shared/data/fformation/Synth)")
    ff.add_argument(
        "--scale",
        type=float,
        default=None,
        help="multiply positions by this to get metres (0.01 for centimetres; default 1, with a warning when the "
        "positions look like centimetres)",
    )
    ff.add_argument(
        "--T",
        dest="thresholds",
        nargs="+",
        type=_threshold,
        default=list(DEFAULT_THRESHOLDS),
        metavar="T",
        help="tolerances in (0, 1], e.g. --T 2/3 1 after the DIRs (default: 2/3 1)",
    )
    ff.add_argument("--table", action="store_true", help="print a readable table instead of JSON")
    add_group_params(ff)
    ff.set_defaults(func=run)


def _threshold(text: str) -> float:
    try:
        return parse_threshold(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def run(args: argparse.Namespace) -> int:
    try:
        params = group_params_from(args)
        datasets: dict[str, list[LabelledFrame]] = {}
        for folder in args.dirs:
            name = _dataset_name(folder, datasets)
            datasets[name] = load_dataset(folder, 1.0 if args.scale is None else args.scale)
            if args.scale is None:
                _warn_if_not_metres(name, datasets[name])
        scores = evaluate_fformation(datasets, params, args.thresholds)
    except ValueError as exc:
        print(f"sid eval fformation: {exc}", file=sys.stderr)
        return 2
    if args.table:
        print(_table(scores))
    else:
        settings = {k: v if math.isfinite(v) else str(v) for k, v in dataclasses.asdict(params).items()}
        print(json.dumps({"params": settings, "scores": scores}, indent=2))
    return 0


def _warn_if_not_metres(name: str, frames: list[LabelledFrame]) -> None:
    """Say so on stderr when a dataset's people stand implausibly far apart for metres (no --scale given)."""
    gap = median_neighbour_distance(frames)
    if gap is not None and gap > LIKELY_METRES_M:
        print(
            f"sid eval fformation: warning: {name}: the median distance from a person to their nearest neighbour is "
            f"{gap:.3g} units, implausible for metres; if the positions are centimetres, pass --scale 0.01",
            file=sys.stderr,
        )


def _dataset_name(folder: str, taken: dict) -> str:
    """The folder's name, made unique among the datasets already named."""
    base = Path(folder).resolve().name or str(folder)
    name, k = base, 2
    while name in taken:
        name, k = f"{base}-{k}", k + 1
    return name


def _table(scores: dict[str, dict[str, dict[str, float]]]) -> str:
    lines = [f"{'dataset':<16} {'T':>4} {'frames':>6} {'precision':>9} {'recall':>7} {'F1':>6}"]
    for name, by_threshold in scores.items():
        for threshold, s in by_threshold.items():
            lines.append(
                f"{name:<16} {threshold:>4} {s['frames']:>6} {s['precision']:>9.3f} {s['recall']:>7.3f} {s['f1']:>6.3f}"
            )
    return "\n".join(lines)
