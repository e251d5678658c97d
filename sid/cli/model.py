"""``sid model quantize IN.onnx OUT.onnx --calibrate SOURCE...``: a static INT8 pose model, calibrated on frames of
sid sources, checked against the float model on those frames; ``sid model simplify IN.onnx OUT.onnx``: the exact
float rewrites alone; ``sid model compare REFERENCE.onnx CANDIDATE.onnx --source SOURCE...``: the two models
through the whole pipeline (people, OKS, positions, facings, groups). See docs/models.md."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator
from pathlib import Path

from sid.cli.common import (
    SYNTHETIC_FRAMES,
    ExitCode,
    add_bag_topic_options,
    fail,
    plain_text,
    positive_int,
    whole_number,
)
from sid.distribution import MissingDependencyError
from sid.errors import InputError
from sid.perception.frame import Frame
from sid.perception.pose.contracts import PoseModelError
from sid.perception.pose.quantize import FLOAT_LAYERS
from sid.sources import BAG_TOPICS, FrameReadError, SourceError, open_source, skip_unreadable

__all__ = [
    "DEFAULT_FRAMES",
    "INPUT_ERRORS",
    "add_parser",
    "run_compare",
    "run_quantize",
    "run_simplify",
]

DEFAULT_FRAMES = 100
"""At most this many frames (all sources together) calibrate or are compared, unless --frames says otherwise."""


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "model", help="quantize a pose model to INT8, or compare two pose models", description=plain_text(__doc__)
    )
    tasks = parser.add_subparsers(dest="task", required=True, metavar="TASK")
    quantize = tasks.add_parser(
        "quantize",
        help="static INT8 quantization (onnxruntime, QDQ), calibrated on frames of sid sources",
        description="Writes OUT.onnx: the model's convolutions in INT8 (uint8 activations, int8 per-channel "
        "weights, QDQ), its decoding float, the same input and output as IN (use it with --model anywhere). "
        "Calibrates on the colour images of the sources through the model's own pre-processing, then compares "
        "OUT with IN on those frames as sid model compare does. Exit 0: written and the same results; 5: written "
        "but the results differ (listed); 2: bad input; 4: the quantize extra is missing.",
    )
    quantize.add_argument("model", type=Path, metavar="IN.onnx", help="the float pose model")
    quantize.add_argument("output", type=Path, metavar="OUT.onnx", help="where to write the INT8 model")
    _add_sources(quantize, "--calibrate", "calibration sources")
    quantize.add_argument(
        "--per-tensor", action="store_true", help="one weight scale per tensor instead of per output channel"
    )
    quantize.add_argument(
        "--float-layers",
        type=whole_number(0),
        default=FLOAT_LAYERS,
        metavar="K",
        help="keep the last K weighted layers on every path to the outputs, and the decoding after them, float "
        "(default %(default)s; 0 quantizes everything; docs/models.md)",
    )
    quantize.add_argument(
        "--float-boxes",
        action="store_true",
        help="keep the branch that reaches only the boxes (YOLO's box regression) float too; by default it is "
        "quantized whole: boxes serve non-maximum suppression, and the keypoints do not depend on them",
    )
    quantize.set_defaults(func=run_quantize)
    simplify = tasks.add_parser(
        "simplify",
        help="exact float rewrites only (double negations, x - 0, x * 1, x / 1 removed)",
        description="Writes OUT.onnx: IN without the nodes that leave their input unchanged bit for bit (outputs "
        "identical, float); the first step of sid model quantize.",
    )
    simplify.add_argument("model", type=Path, metavar="IN.onnx")
    simplify.add_argument("output", type=Path, metavar="OUT.onnx")
    simplify.set_defaults(func=run_simplify)
    compare = tasks.add_parser(
        "compare",
        help="two pose models through the pipeline on the same frames",
        description="Runs pose -> lift -> groups with each model on every frame and prints, per frame, the people "
        "each finds, the mean and lowest OKS (COCO constants) of the candidate's keypoints against the "
        "reference's, the largest position and facing differences after lifting, and whether the groups agree. "
        "Exit 0: the same results on every frame; 5: they differ (listed); 2: bad input.",
    )
    compare.add_argument("reference", type=Path, metavar="REFERENCE.onnx", help="e.g. the float model")
    compare.add_argument("candidate", type=Path, metavar="CANDIDATE.onnx", help="e.g. its INT8 quantization")
    _add_sources(compare, "--source", "sources")
    compare.set_defaults(func=run_compare)


def _add_sources(parser: argparse.ArgumentParser, option: str, what: str) -> None:
    parser.add_argument(
        option,
        dest="sources",
        nargs="+",
        required=True,
        metavar="SOURCE",
        help=f"{what}: any sid detect --source (DIR, FILE.db3, FILE.bag, synthetic:SCENE); several may follow",
    )
    add_bag_topic_options(parser)
    parser.add_argument(
        "--frames",
        type=positive_int,
        default=DEFAULT_FRAMES,
        metavar="N",
        help="use at most N frames of all the sources together (default %(default)s; synthetic: "
        f"{SYNTHETIC_FRAMES} per source)",
    )


def _frames(args: argparse.Namespace, command: str) -> Iterator[tuple[str, Frame]]:
    """(name, frame) of the sources in turn, at most ``args.frames``; unreadable frames are reported and skipped."""
    count = 0
    for spec in args.sources:
        options = {"frames": SYNTHETIC_FRAMES} if spec.startswith("synthetic:") else {}
        source = open_source(spec, **options, **{name: getattr(args, name) for name in BAG_TOPICS})

        def report(error: FrameReadError, spec: str = spec) -> None:  # the frame named as the results name it
            where = spec if error.index is None else f"{spec}#{error.index}"
            print(f"{command}: {where}: skipped, {error}", file=sys.stderr)

        try:
            for frame in skip_unreadable(source, report):
                if count >= args.frames:
                    return
                count += 1
                yield f"{spec}#{frame.index}", frame
        finally:
            close = getattr(source, "close", None)
            if close is not None:
                close()


def _open_all(args: argparse.Namespace, command: str) -> list[tuple[str, Frame]]:
    frames = list(_frames(args, command))
    if not frames:
        raise InputError(f"no frames in {' '.join(args.sources)}")
    return frames


def _comparison(reference: Path, candidate: Path, frames: list[tuple[str, Frame]]) -> tuple[str, bool]:
    """The comparison table of two models on ``frames`` and whether every frame passes."""
    from sid.experiments.pose_compare import Criteria, compare_pipelines, format_comparisons
    from sid.perception.pipeline import Pipeline, image_pose
    from sid.perception.pose import load_pose_estimator

    first, second = (Pipeline(image_pose(load_pose_estimator(path))) for path in (reference, candidate))
    criteria = Criteria()
    rows = compare_pipelines(first, second, frames, criteria)
    return format_comparisons(rows, criteria), not any(row.problems(criteria) for row in rows)


INPUT_ERRORS = (PoseModelError, SourceError, ValueError, OSError, MissingDependencyError)


def run_quantize(args: argparse.Namespace) -> int:
    from sid.perception.pose import load_pose_estimator
    from sid.perception.pose.quantize import check_paths, quantize_model
    from sid.perception.pose.session import quiet_load_warnings

    command = "sid model quantize"
    quiet_load_warnings()
    try:
        check_paths(args.model, args.output)  # a bad model or output is said before the sources are read
        load_pose_estimator(args.model, threads=1)
        frames = _open_all(args, command)
        report = quantize_model(
            args.model,
            args.output,
            (frame.color for _, frame in frames),
            per_channel=not args.per_tensor,
            float_layers=args.float_layers,
            float_boxes=args.float_boxes,
        )
        table, same = _comparison(args.model, args.output, frames)
    except INPUT_ERRORS as exc:
        return fail(command, exc)
    boxes = f" ({report.box_branch_nodes} of them in the box branch)" if report.box_branch_nodes else ""
    print(
        f"wrote {report.output}: {report.contract}, INT8 (QDQ, {'per-tensor' if args.per_tensor else 'per-channel'} "
        f"weights), {report.quantized_nodes} nodes quantized{boxes}, {report.float_nodes} kept float, "
        f"{report.removed_nodes} no-op nodes removed; calibrated on {report.calibration_images} frame(s) in "
        f"{report.seconds:.1f} s"
    )
    print(f"against {args.model} on the calibration frames:")
    print(table)
    return ExitCode.OK if same else ExitCode.DIFFERENT


def run_simplify(args: argparse.Namespace) -> int:
    from sid.perception.pose.quantize import simplify_model
    from sid.perception.pose.session import quiet_load_warnings

    quiet_load_warnings()
    try:
        removed = simplify_model(args.model, args.output)
    except INPUT_ERRORS as exc:
        return fail("sid model simplify", exc)
    print(f"wrote {args.output}: {removed} no-op node(s) removed, outputs unchanged")
    return 0


def run_compare(args: argparse.Namespace) -> int:
    from sid.perception.pose.session import quiet_load_warnings

    command = "sid model compare"
    quiet_load_warnings()
    try:
        frames = _open_all(args, command)
        table, same = _comparison(args.reference, args.candidate, frames)
    except INPUT_ERRORS as exc:
        return fail(command, exc)
    print(table)
    return ExitCode.OK if same else ExitCode.DIFFERENT
