"""``sid detect``: people and conversational groups per frame from a camera, a recording, a folder or a scene."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TextIO

import cv2
import numpy as np

from costmap.grid import Costmap2D, GridSpec
from costmap.render import CameraView, render_costmap
from sid.cli.common import OutputFolderError, check_output_folder, fail
from sid.perception.camera import Calibration
from sid.perception.frame import Frame
from sid.perception.groups import GroupParams
from sid.perception.lifting import LiftParams
from sid.perception.mount import CameraMount
from sid.perception.overlay import draw_detections
from sid.perception.pipeline import FrameResult, Pipeline, PoseFn, image_pose
from sid.perception.pose.contracts import PoseModelError
from sid.perception.pose.session import PROVIDER_CHOICES
from sid.sources import RECORDING_SUFFIXES, FrameReadError, SourceError, open_source, skip_unreadable

TOP_VIEW = GridSpec.from_size(0.05, (-0.5, -3.5), (7.5, 7.0))  # world frame: 7 m ahead of the camera, 3.5 m each side


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "detect",
        help="stream people and groups per frame as JSON lines",
        description="Run pose -> 3D people -> groups on every frame of a source and print one JSON line per frame "
        "(world frame: x forward, y left, metres; theta in radians, null when unknown). Frames without people or "
        "depth, and unreadable frames, are reported on stderr and skipped.",
    )
    parser.add_argument("--source", required=True, help="realsense | FILE.db3 | FILE.bag | DIR | synthetic:SCENE")
    parser.add_argument("--model", type=Path, help="pose model (.onnx); optional for synthetic sources")
    parser.add_argument("--contract", help="pose model contract, if it cannot be read from the model")
    parser.add_argument(
        "--threads",
        type=positive_int,
        default=None,
        metavar="N",
        help="pose model threads (default: the physical cores this process may use)",
    )
    parser.add_argument(
        "--provider",
        choices=PROVIDER_CHOICES,
        default="auto",
        help="onnxruntime execution provider for the pose model: 'auto' (default) uses OpenVINO when "
        "onnxruntime-openvino is installed (pip install 'sid[openvino]'), else CPU",
    )
    parser.add_argument("--frames", type=int, help="stop after this many frames (default: all; synthetic: 30)")
    parser.add_argument("--out", type=Path, help="also write detections.jsonl, overlay and top-view PNGs here")
    parser.add_argument(
        "--align",
        choices=("none", "sid", "librealsense"),
        default="none",
        help="RealSense sources: 'none' (default) looks depth up sparsely at the keypoints, the "
        "cheapest; 'sid' or 'librealsense' align every depth frame to colour first",
    )
    parser.add_argument("--show", action="store_true", help="show overlays in a window (needs an OpenCV GUI build)")
    parser.add_argument("--camera-height", type=float, default=CameraMount.height, help="metres above the ground")
    parser.add_argument("--camera-tilt", type=float, default=CameraMount.tilt, help="downward pitch, radians")
    parser.add_argument(
        "--keypoint-threshold",
        type=float,
        default=None,
        help=f"keypoint confidence threshold (default {LiftParams().min_score})",
    )
    parser.add_argument("--no-keypoints", action="store_true", help="leave 3D keypoints out of the JSON lines")
    parser.set_defaults(func=run)


def positive_int(text: str) -> int:
    """argparse type: a whole number >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}")
    return value


def _pose(args: argparse.Namespace) -> PoseFn:
    if args.model is not None:
        from sid.perception.pose import load_pose_estimator

        return image_pose(
            load_pose_estimator(args.model, contract=args.contract, threads=args.threads, providers=args.provider)
        )
    if args.source.startswith("synthetic:"):
        from sid.synthetic.pose import TruthPose

        return TruthPose()
    raise SourceError("detect: a real source needs a pose model: --model FILE.onnx (see docs/models.md)")


def _source_options(args: argparse.Namespace) -> dict:
    if args.source.startswith("synthetic:"):
        return {"frames": args.frames or 30}
    if args.source == "realsense" or Path(args.source).suffix.lower() in RECORDING_SUFFIXES:
        return {"align": args.align}
    return {}


def _skip_reason(frame: Frame) -> str | None:
    depth = frame.depth
    if depth is None or depth.size == 0 or not np.any(np.isfinite(depth) & (depth > 0)):
        return "no depth"
    return None


def camera_view(calibration: Calibration, mount: CameraMount) -> CameraView:
    """The colour camera seen from above: at the world origin, its field of view bounded by the image's left and
    right edges on the principal row."""
    color = calibration.color
    edges = np.array([[-0.5 - color.cx, 0.0, color.fx], [color.width - 0.5 - color.cx, 0.0, color.fx]])
    world = edges @ mount.rotation.T
    left, right = np.arctan2(world[:, 1], world[:, 0])
    return CameraView(0.0, 0.0, float(left + right) / 2, float(left - right))


def _write_pictures(out: Path, frame: Frame, result: FrameResult, mount: CameraMount) -> None:
    by_id = {p.id: p for p in result.people}
    people = [by_id.get(i) for i in range(len(result.detections))]
    cv2.imwrite(str(out / f"overlay_{frame.index:06d}.png"), draw_detections(frame.color, result.detections, people))
    top = render_costmap(
        Costmap2D.filled(TOP_VIEW),
        result.people,
        result.groups,
        title=f"frame {frame.index}: {_count(len(result.people), 'person', 'people')}, "
        f"{_count(len(result.groups), 'group', 'groups')}",
        camera=camera_view(frame.calibration, mount),
        scale=6,
    )
    cv2.imwrite(str(out / f"topview_{frame.index:06d}.png"), top)


def _count(n: int, one: str, many: str) -> str:
    return f"{n} {one if n == 1 else many}"


def _emit(record: dict, streams: list[TextIO]) -> None:
    line = json.dumps(record)
    for stream in streams:
        stream.write(line + "\n")
        stream.flush()


def run(args: argparse.Namespace) -> int:
    if args.show:
        print(
            "detect: --show needs an OpenCV build with a GUI; this install is headless, use --out DIR to write "
            "the overlay pictures instead",
            file=sys.stderr,
        )
        return 2
    if args.out is not None:
        try:
            check_output_folder(args.out)  # before the model loads and the camera opens
        except OutputFolderError as exc:
            return fail("sid detect", exc)
    try:
        lift = LiftParams() if args.keypoint_threshold is None else LiftParams(min_score=args.keypoint_threshold)
        mount = CameraMount(args.camera_height, args.camera_tilt)
        pipeline = Pipeline(_pose(args), mount, lift, GroupParams())
        options = _source_options(args)
        source = open_source(args.source, **options)
    except (SourceError, PoseModelError, ValueError, OSError) as exc:
        print(f"detect: {exc}", file=sys.stderr)
        return 2

    streams: list[TextIO] = [sys.stdout]
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        streams.append((args.out / "detections.jsonl").open("w"))

    done = skipped = 0

    def report(error: FrameReadError) -> None:
        nonlocal skipped
        skipped += 1
        print(f"detect: frame {error.index}: skipped, {error}", file=sys.stderr)

    interrupted = False
    totals: list[float] = []
    try:
        for frame in skip_unreadable(source, report):
            if args.frames is not None and done + skipped >= args.frames:
                break
            reason = _skip_reason(frame)
            result = None if reason else pipeline(frame)
            if result is not None and not result.people:
                reason = "no people"
            if reason or result is None:  # result is None only when there is a reason
                skipped += 1
                print(f"detect: frame {frame.index}: skipped, {reason}", file=sys.stderr)
                continue
            done += 1
            totals.append(result.timing_ms["total"])
            _emit(result.to_json(keypoints=not args.no_keypoints), streams)
            if args.out is not None:
                _write_pictures(args.out, frame, result, mount)
    except KeyboardInterrupt:
        interrupted = True
        print("detect: interrupted, output flushed", file=sys.stderr)
    except SourceError as exc:
        print(f"detect: source stopped: {exc}", file=sys.stderr)
        return 1
    finally:
        for stream in streams[1:]:
            stream.close()
        close = getattr(source, "close", None)
        if close is not None:
            close()
    median = f", median {np.median(totals):.2f} ms per frame" if totals else ""
    print(f"detect: {done} frames with people, {skipped} skipped{median}", file=sys.stderr)
    return 130 if interrupted else 0
