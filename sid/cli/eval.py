"""``sid eval fformation DIR...``: score the group detector on F-formation benchmark datasets; ``sid eval tracking``:
score the trackers on the synthetic sequences; ``sid eval crowd`` (``sid.cli.eval_crowd``): on real trajectories."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import math
import sys
from pathlib import Path
from typing import Any

from sid.cli.common import (
    check_output_folder,
    fail,
    name_width,
    positive_int,
    positive_number,
    print_written,
    staged_output,
    whole_number,
)
from sid.cli.eval_crowd import add_crowd_parser
from sid.cli.grouping import add_group_params, group_params_from
from sid.distribution import MissingDependencyError
from sid.documents import plural
from sid.errors import InputError
from sid.experiments.fformation import (
    DEFAULT_GRID,
    DEFAULT_THRESHOLDS,
    FACING_AGREEMENT_MIN,
    GROUP_ERRORS,
    Fold,
    LabelledFrame,
    cross_validate,
    detect_all,
    facing_agreement,
    gcff_settings,
    group_errors,
    load_dataset_any_yaw,
    load_dataset_in_metres,
    missing_members,
    parse_threshold,
    repeated_members,
    score_all,
    shifted_ids,
    unit_warning,
    with_facing_noise,
    without_facings,
)
from sid.perception.groups import GroupParams

__all__ = ["PICTURES_MAX", "add_parser", "add_tracking_parser", "run", "run_tracking"]

PICTURES_MAX = 20
"""``--pictures``: the most frames drawn per dataset unless ``--pictures-max`` says."""


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
        type=_scale,
        nargs="+",
        default=["auto"],
        metavar="S",
        help="multiply positions by this to get metres: one value for every DIR or one per DIR (1 for metres, "
        "0.01 for centimetres, 0.001 for millimetres), or auto (the default): the unit in which the median distance "
        "from a person to their nearest neighbour is plausible for people (0.1-5 m), said on stderr when it is not "
        "metres; a warning names the scale that fits when the scaled positions are implausible",
    )
    angles = ff.add_mutually_exclusive_group()
    angles.add_argument(
        "--degrees",
        dest="degrees",
        action="store_const",
        const=True,
        help="the files' theta is in degrees (default: radians, or degrees when a theta reaches beyond two turns, "
        "said on stderr)",
    )
    angles.add_argument(
        "--radians", dest="degrees", action="store_const", const=False, help="the files' theta is in radians"
    )
    ff.add_argument(
        "--T",
        dest="thresholds",
        nargs="+",
        type=_threshold,
        default=list(DEFAULT_THRESHOLDS),
        metavar="T",
        help="tolerances in (1/2, 1], e.g. --T 2/3 1 after the DIRs (default: 2/3 1)",
    )
    ff.add_argument("--table", action="store_true", help="print a readable table instead of JSON")
    ff.add_argument(
        "--errors",
        action="store_true",
        help="also count how each true group came out: exact, all its members and one other or more, only some of "
        "them, some and others, missed; and the detected groups that match no true group",
    )
    ff.add_argument(
        "--grid",
        nargs="+",
        type=_grid_item,
        metavar="FIELD=V1,V2",
        help="cross-validate instead: for each DIR left out, choose the values (of these GroupParams fields, e.g. "
        "group_price=0.5,0.65,0.8) with the best mean F1 at the first T on the other DIRs, and score them on it",
    )
    grid_text = " ".join(f"{k}={','.join(f'{v:g}' for v in vs)}" for k, vs in DEFAULT_GRID.items())
    ff.add_argument(
        "--cross-validate",
        action="store_true",
        help=f"leave one DIR out at a time over the grid that chose the defaults ({grid_text}; --grid sets another)",
    )
    ff.add_argument(
        "--workers",
        type=positive_int,
        metavar="N",
        help="with --cross-validate or --grid: score the grid points in N worker processes (default 1; the same "
        "table); progress on stderr",
    )
    ff.add_argument(
        "--gcff-settings",
        action="store_true",
        help="score the gcff method with each sequence's own settings_gc.mat (GCFF tuned per sequence, the "
        "literature's reference; its stride and mdl in the positions' units, scaled as they are) instead of the "
        "detector the other options choose",
    )
    ff.add_argument(
        "--facing-noise",
        type=positive_number("number of degrees", zero=True),
        default=0.0,
        metavar="DEG",
        help="add seeded Gaussian noise of this standard deviation (degrees) to every facing first (default 0)",
    )
    ff.add_argument(
        "--facing-missing",
        type=float,
        default=0.0,
        metavar="SHARE",
        help="make this share (0-1) of the facings unknown first, at random and seeded, as people half hidden "
        "behind others get none from the pipeline (default 0)",
    )
    ff.add_argument(
        "--pictures",
        type=Path,
        metavar="DIR",
        help="also draw the frames the detector gets wrong (a true group not found exactly, or a false group), "
        "worst first: top views frame_DATASET_NN.png (people, facings and ids; true groups dashed, coloured by how "
        "they came out; detected groups solid) and index.csv listing them, into DIR (created if missing; a re-run "
        "replaces them); not with --grid or --cross-validate",
    )
    ff.add_argument(
        "--pictures-max",
        type=positive_int,
        metavar="N",
        help=f"with --pictures: at most N pictures per dataset, its N worst frames (default {PICTURES_MAX})",
    )
    add_group_params(ff)
    ff.set_defaults(func=run)
    add_tracking_parser(tasks)
    add_crowd_parser(tasks)


def _threshold(text: str) -> float:
    try:
        return parse_threshold(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _scale(text: str) -> float | str:
    """'auto', or a positive number."""
    return text if text == "auto" else positive_number("number or auto")(text)


def _grid_item(text: str) -> tuple[str, list[float]]:
    """'group_price=0.5,0.8' -> ('group_price', [0.5, 0.8])."""
    name, _, values = text.partition("=")
    try:
        numbers = [float(v) for v in values.split(",")]
    except ValueError:
        numbers = []
    if not name or not numbers:
        raise argparse.ArgumentTypeError(f"expected FIELD=V1,V2,... (numbers), got {text!r}")
    return name.replace("-", "_"), numbers


def run(args: argparse.Namespace) -> int:
    try:
        params = group_params_from(args)
        if len(args.scale) not in (1, len(args.dirs)):
            raise InputError(f"--scale takes one value or one per DIR ({len(args.dirs)}), got {len(args.scale)}")
        scales = args.scale * len(args.dirs) if len(args.scale) == 1 else args.scale
        if args.workers is not None and not (args.grid or args.cross_validate):
            raise InputError("--workers spreads a cross-validation's grid points: give --cross-validate or --grid too")
        if args.pictures_max is not None and args.pictures is None:
            raise InputError("--pictures-max caps --pictures: give --pictures DIR too")
        if args.pictures is not None:
            if args.grid or args.cross_validate:
                raise InputError(
                    "--pictures draws one detector's groups: it takes no --grid or --cross-validate (draw the "
                    "chosen parameters' errors with them set, e.g. --alone-price 0.5)"
                )
            check_output_folder(args.pictures, "--pictures")  # before the work, not after it
        datasets: dict[str, list[LabelledFrame]] = {}
        units: dict[str, float] = {}  # each dataset's scale to metres, for its settings_gc.mat too
        for folder, scale in zip(args.dirs, scales, strict=True):
            name = _dataset_name(folder, datasets)
            if scale == "auto":
                datasets[name], unit, scale, degrees = load_dataset_in_metres(folder, args.degrees)
                if unit != "metres":
                    print(f"sid eval fformation: {name}: positions read as {unit} (--scale {scale:g})", file=sys.stderr)
            else:
                datasets[name], degrees = load_dataset_any_yaw(folder, scale, args.degrees)
            if degrees and args.degrees is None:
                reason = "as radians it reaches beyond two turns"
                print(f"sid eval fformation: {name}: theta read as degrees ({reason})", file=sys.stderr)
            units[name] = scale
            _warn_about_data(name, datasets[name], scale, params.positions_only_reach > 0)
            if args.facing_missing:
                datasets[name] = without_facings(datasets[name], args.facing_missing)
            if args.facing_noise:
                datasets[name] = with_facing_noise(datasets[name], math.radians(args.facing_noise))
        grid = args.grid or ([(k, list(v)) for k, v in DEFAULT_GRID.items()] if args.cross_validate else None)
        if grid and args.gcff_settings:
            raise InputError("--gcff-settings scores GCFF's own settings: it takes no --grid or --cross-validate")
        if grid and args.errors:
            raise InputError("--errors counts one detector's groups: it takes no --grid or --cross-validate")
        if grid:
            from sid.experiments.progress import ProgressBar

            folds, table = cross_validate(
                datasets, dict(grid), params, args.thresholds[0], args.workers or 1, ProgressBar("cross-validation")
            )
            print(_folds(folds, table) if args.table else json.dumps(_folds_json(folds, table, grid), indent=2))
            return 0
        per_sequence = None
        if args.gcff_settings:
            per_sequence = {
                name: gcff_settings(folder, units[name]) for name, folder in zip(datasets, args.dirs, strict=True)
            }
            params = dataclasses.replace(params, method="gcff")
        detected = detect_all(datasets, params, per_sequence)
        scores = score_all(datasets, detected, args.thresholds)
        errors = None
        if args.errors:
            errors = {name: group_errors(frames, detected[name]) for name, frames in datasets.items()}
    except ValueError as exc:
        print(f"sid eval fformation: {exc}", file=sys.stderr)
        return 2
    if args.table:
        print(_table(scores))
        if errors is not None:
            print(f"\n{_errors_table(errors)}")
    else:
        settings = {
            k: v if isinstance(v, str) or math.isfinite(v) else str(v) for k, v in dataclasses.asdict(params).items()
        }
        report: dict[str, object] = {"params": settings, "scores": scores}
        if errors is not None:
            report["group_errors"] = errors
        print(json.dumps(report, indent=2), flush=True)
    if args.pictures is not None:
        try:
            _write_pictures(args, datasets, detected, params)
        except OSError as exc:
            return fail("sid eval fformation", exc)
    return 0


def _write_pictures(
    args: argparse.Namespace,
    datasets: dict[str, list[LabelledFrame]],
    detected: dict[str, list[list[tuple[int, ...]]]],
    params: GroupParams,
) -> None:
    """``--pictures``: the worst frames' pictures and their index, written whole into the folder (an earlier run's
    replaced); on stderr, how many frames had errors and the files written (stdout holds the scores)."""
    from sid.experiments.fformation_pictures import INDEX, PICTURES, write_error_pictures
    from sid.experiments.progress import ProgressBar

    method = "gcff, each sequence's settings_gc.mat" if args.gcff_settings else params.method
    defaults = dataclasses.asdict(GroupParams(method=params.method))
    changed = {k: v for k, v in dataclasses.asdict(params).items() if v != defaults[k]}
    if changed and not args.gcff_settings:  # the title names what the run set, so no picture passes for the defaults'
        method += " " + " ".join(f"{k}={v:g}" for k, v in changed.items())
    if args.facing_noise:
        method += f", facing noise {args.facing_noise:g} deg"
    if args.facing_missing:
        method += f", {args.facing_missing:.0%} of facings unknown"
    most = PICTURES_MAX if args.pictures_max is None else args.pictures_max
    with staged_output(args.pictures, (PICTURES, INDEX)) as staged:
        written, counts = write_error_pictures(
            datasets, detected, staged.path, most, args.thresholds, method, ProgressBar("pictures")
        )
        files = [staged.final(path) for path in written]
    for name, (wrong, drawn) in counts.items():
        print(f"sid eval fformation: {name}: {plural(wrong, 'frame')} with errors, {drawn} drawn", file=sys.stderr)
    with contextlib.redirect_stdout(sys.stderr):
        print_written(files)


def _warn_about_data(name: str, frames: list[LabelledFrame], scale: float, by_positions: bool) -> None:
    """On stderr: positions implausible as metres once scaled (with the --scale that fits), people left out for a
    non-finite position, people without a facing (a theta that is not a finite number; without any, unless
    ``by_positions``: --positions-only-reach is set, that no group can be found), no ground-truth group, and
    ground-truth members missing from their frame's people."""
    if reason := unit_warning(frames, scale):
        print(f"sid eval fformation: warning: {name}: {reason} (set it with --scale)", file=sys.stderr)
    unplaced = sum(f.unplaced for f in frames)
    if unplaced:
        print(
            f"sid eval fformation: warning: {name}: {plural(unplaced, 'person', 'people')} without a finite position "
            f"left out (in {plural(sum(f.unplaced > 0 for f in frames), 'frame')})",
            file=sys.stderr,
        )
    unknown = [sum(p.theta is None for p in f.people) for f in frames]
    if sum(unknown):
        people = plural(sum(len(f.people) for f in frames), "person", "people")
        print(
            f"sid eval fformation: warning: {name}: {sum(unknown)} of {people} (in "
            f"{plural(sum(n > 0 for n in unknown), 'frame')}) have a theta that is not a finite number: their "
            "facing is taken as unknown"
            + (
                "; with no facing at all the o-space methods find no group (a group needs one known facing): "
                "--positions-only-reach M groups by positions alone"
                if sum(unknown) == sum(len(f.people) for f in frames) and not by_positions
                else ""
            ),
            file=sys.stderr,
        )
    agreement = facing_agreement(frames)
    if agreement is not None and agreement < FACING_AGREEMENT_MIN:
        print(
            f"sid eval fformation: warning: {name}: ground-truth members face their group's centre little (mean "
            f"cosine {agreement:.2f}, {FACING_AGREEMENT_MIN:g} or more expected): theta in another convention (a "
            "compass heading, clockwise from +y? a y axis flipped without its yaws?); facings are yaws "
            "counter-clockwise from +x",
            file=sys.stderr,
        )
    if not any(f.truth for f in frames):
        print(
            f"sid eval fformation: warning: {name}: no ground-truth group of two or more people in any frame: every "
            "group found counts as false (check how GTgroups lists the groups)",
            file=sys.stderr,
        )
    missing, total = missing_members(frames)
    if missing:
        shift = shifted_ids(frames)
        why = (
            f"every member would be there with its id {shift:+d}: ids counted from {0 if shift > 0 else 1} in "
            f"the ground truth and from {1 if shift > 0 else 0} in the features?"
            if shift
            else "annotation slips if few; if many, the groups use other ids than the features"
        )
        print(
            f"sid eval fformation: warning: {name}: {missing} of the {total} ground-truth group members are not among "
            f"their frame's people ({why})",
            file=sys.stderr,
        )
    repeated, frames_with = repeated_members(frames)
    if repeated:
        print(
            f"sid eval fformation: warning: {name}: {plural(repeated, 'ground-truth member')} listed in two or more "
            f"groups of one frame (in {plural(frames_with, 'frame')}): nobody stands in two F-formations; another "
            "encoding of the groups (padding, ids)?",
            file=sys.stderr,
        )


def _dataset_name(folder: str, taken: dict) -> str:
    """The folder's name, made unique among the datasets already named and apart from the scores' "pooled"."""
    base = Path(folder).resolve().name or str(folder)
    name, k = base, 2
    while name in taken or name == "pooled":
        name, k = f"{base}-{k}", k + 1
    return name


def _folds(folds: list[Fold], table: dict[tuple[float, ...], dict[str, float]]) -> str:
    """Each fold's choice and scores, then the spread of the held-out F1."""
    w = name_width(fold.held_out for fold in folds)
    lines = [f"{'held out':<{w}} {'F1 there':>8} {'F1 others':>9}  chosen"]
    for fold in folds:
        chosen = " ".join(f"{k}={v:g}" for k, v in fold.chosen.items())
        lines.append(f"{fold.held_out:<{w}} {fold.held_out_f1:>8.3f} {fold.train_f1:>9.3f}  {chosen}")
    held = [fold.held_out_f1 for fold in folds]
    lines.append(
        f"held-out F1 {min(held):.3f}-{max(held):.3f} (spread {max(held) - min(held):.3f}), {len(table)} grid points"
    )
    return "\n".join(lines)


def _folds_json(
    folds: list[Fold], table: dict[tuple[float, ...], dict[str, float]], grid: list[tuple[str, list[float]]]
) -> dict[str, Any]:
    names = [name for name, _ in grid]
    return {
        "folds": [dataclasses.asdict(fold) for fold in folds],
        "grid": [dict(zip(names, values, strict=True)) | {"f1": scores} for values, scores in table.items()],
    }


def _errors_table(errors: dict[str, dict[str, int]]) -> str:
    """How the true groups came out, per dataset: counts and, for the true groups, their shares."""
    columns = [*GROUP_ERRORS, "false_groups"]
    w = name_width(errors)
    lines = [f"{'dataset':<{w}} {'true groups':>11} " + " ".join(f"{c.replace('_', ' '):>13}" for c in columns)]
    for name, counts in errors.items():
        true = sum(counts[c] for c in GROUP_ERRORS)
        cells = [
            f"{counts[c]} ({counts[c] / true:.0%})" if true and c in GROUP_ERRORS else str(counts[c]) for c in columns
        ]
        lines.append(f"{name:<{w}} {true:>11} " + " ".join(f"{cell:>13}" for cell in cells))
    return "\n".join(lines)


def _table(scores: dict[str, dict[str, dict[str, float]]]) -> str:
    w = name_width(scores)
    lines = [f"{'dataset':<{w}} {'T':>4} {'frames':>6} {'precision':>9} {'recall':>7} {'F1':>6}"]
    for name, by_threshold in scores.items():
        for threshold, s in by_threshold.items():
            lines.append(
                f"{name:<{w}} {threshold:>4} {s['frames']:>6} "
                f"{s['precision']:>9.3f} {s['recall']:>7.3f} {s['f1']:>6.3f}"
            )
    return "\n".join(lines)


def add_tracking_parser(tasks: argparse._SubParsersAction) -> None:
    """``sid eval tracking``: the options of ``sid.experiments.synthetic_tracking.TrackingEvalSettings``."""
    from sid.experiments.synthetic_tracking import TrackingEvalSettings
    from sid.synthetic.sequence import SEQUENCES

    defaults = TrackingEvalSettings()
    parser = tasks.add_parser(
        "tracking",
        help="people and group tracking on the synthetic sequences (MOTA, IDF1, group F1, flicker)",
        description="Renders the built-in synthetic sequences, runs the per-frame pipeline and the tracking stream on "
        "them and prints MOTA / IDF1 (py-motmetrics), group F1 with and without tracking, frames in which walkers "
        "are called a conversation, and the costmap flicker of the per-frame and the tracked layers "
        "(docs/tracking.md). Takes 15-40 s on two cores; progress on stderr.",
    )
    parser.add_argument(
        "--sequences", nargs="+", choices=SEQUENCES, default=list(defaults.sequences), metavar="NAME",
        help=f"which sequences (default: all of {', '.join(SEQUENCES)})",
    )  # fmt: skip
    parser.add_argument("--fps", type=float, default=defaults.fps, help=f"frame rate in Hz ({defaults.fps:g})")
    parser.add_argument("--frames", type=int, default=None, help="at most this many frames per sequence (all)")
    parser.add_argument("--seed", type=whole_number(0), default=defaults.seed, help=f"noise seed ({defaults.seed})")
    parser.add_argument(
        "--flicker-frames", type=int, default=defaults.flicker_frames,
        help=f"frames of the flicker layout {defaults.flicker_layout} ({defaults.flicker_frames})",
    )  # fmt: skip
    parser.add_argument("--table", action="store_true", help="print a readable table instead of JSON")
    parser.set_defaults(func=run_tracking)


def run_tracking(args: argparse.Namespace) -> int:
    from sid.experiments.progress import ProgressBar
    from sid.experiments.synthetic_tracking import TrackingEvalSettings, evaluate_tracking

    try:
        settings = TrackingEvalSettings(
            sequences=tuple(args.sequences), fps=args.fps, seed=args.seed, frames=args.frames,
            flicker_frames=args.flicker_frames,
        )  # fmt: skip
        result = evaluate_tracking(settings, ProgressBar("tracking"))
    except (ValueError, MissingDependencyError) as exc:
        return fail("sid eval tracking", exc)
    print(_tracking_table(result) if args.table else json.dumps(result, indent=2))
    return 0


def _tracking_table(result: dict) -> str:
    rows = [*result["sequences"].items(), ("overall", result["overall"])]
    lines = [
        f"{'sequence':<18} {'MOTA':>6} {'IDF1':>6} {'IDsw':>5} {'IDtr':>5} {'FN':>4} {'FP':>4} "
        f"{'group F1 2/3 raw / tracked':>27} {'walkers in conv. raw / tracked':>31}"
    ]
    for name, s in rows:
        f1 = s.get("group_f1_T2/3", {})
        walkers = s.get("frames_walkers_in_a_conversation", {})
        groups = f"{f1['without_tracking']['f1']:.3f} / {f1['with_tracking']['f1']:.3f}" if f1 else "-"
        conv = f"{walkers['without_tracking']} / {walkers['with_tracking']}" if walkers else "-"
        lines.append(
            f"{name:<18} {s['mota']:>6.3f} {s['idf1']:>6.3f} {s['id_switches']:>5} {s['id_transfers']:>5} "
            f"{s['misses']:>4} {s['false_positives']:>4} {groups:>27} {conv:>31}"
        )
    flicker = result["flicker"]
    lines.append(
        f"flicker ({flicker['layout']}, {flicker['pairs_scored']} frame pairs, cells changing by > "
        f"{flicker['threshold']}, miss rate {flicker['miss_rate']:g}): per-frame layer "
        f"{flicker['per_frame']['changed_cells_total']}, tracked layer {flicker['tracked']['changed_cells_total']}"
    )
    return "\n".join(lines)
