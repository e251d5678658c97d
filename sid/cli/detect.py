"""``sid detect``: people and conversational groups per frame from a camera, a recording, a folder or a scene."""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
import time
from collections.abc import Iterable, Iterator, Sized
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import cv2
import numpy as np

from costmap.grid import Costmap2D, GridSpec
from sid.ahead import run_ahead
from sid.cli.common import (
    SYNTHETIC_FRAMES,
    ExitCode,
    OutputFolderError,
    add_bag_topic_options,
    check_output_folder,
    clear_owned,
    fail,
    output_folder_lock,
    pose_model,
    positive_int,
    positive_number,
    signals_deferred,
)
from sid.cli.grouping import add_group_params, add_params_file_option, group_params_from, params_file_from
from sid.distribution import MissingDependencyError, install_hint
from sid.documents import plural, write_atomically
from sid.perception.camera import Calibration
from sid.perception.frame import Frame
from sid.perception.group import Group
from sid.perception.lifting import LiftParams
from sid.perception.mount import CameraMount
from sid.perception.overlay import draw_detections
from sid.perception.people import Person
from sid.perception.pipeline import FrameResult, Pipeline, PosedFrame
from sid.perception.pose.contracts import PoseModelError
from sid.perception.pose.session import PROVIDER_CHOICES
from sid.sources import (
    BAG_TOPICS,
    FOLDER_FPS,
    RECORDING_SUFFIXES,
    FrameReadError,
    SourceError,
    frames_or_errors,
    is_frame_folder,
    open_source,
)
from sid.tracking import PeopleStream, SessionUpdate, TrackingError, camera_fov

if TYPE_CHECKING:  # costmap.render (the costmap layers, shapely) is imported only for --out: start-up time
    from costmap.render import CameraView

__all__ = ["OUTPUTS", "PictureRecords", "TOP_VIEW", "add_parser", "camera_view", "picture_records", "run"]

OUTPUTS = ("detections.jsonl", "overlay_*.png", "topview_*.png")
"""What ``sid detect --out`` writes (and clears there first, nothing else)."""
TOP_VIEW = GridSpec.from_size(0.05, (-0.5, -3.5), (7.5, 7.0))  # world frame: 7 m ahead of the camera, 3.5 m each side


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "detect",
        help="stream people and groups per frame as JSON lines",
        description="Run pose -> 3D people -> groups on every frame of a source and print one JSON line per frame "
        "(world frame: x forward, y left, metres; theta in radians, null when unknown). Frames without people or "
        "depth, and unreadable frames, are reported on stderr and skipped; a source none of whose frames can be read "
        "is bad input (exit 2).",
    )
    parser.add_argument("--source", required=True, help="realsense | FILE.db3 | FILE.bag | DIR | synthetic:SCENE")
    add_bag_topic_options(parser)
    parser.add_argument("--model", type=Path, help="pose model (.onnx); optional for synthetic sources")
    parser.add_argument("--contract", help="pose model contract, if it cannot be read from the model")
    parser.add_argument(
        "--threads",
        type=positive_int,
        default=None,
        metavar="N",
        help="pose model (--model) threads (default: the physical cores this process may use)",
    )
    parser.add_argument(
        "--provider",
        choices=PROVIDER_CHOICES,
        default="auto",
        help="onnxruntime execution provider for the pose model (--model): 'auto' (default) uses TensorRT or CUDA "
        "when this onnxruntime offers them, else OpenVINO when onnxruntime-openvino is installed "
        f"({install_hint('openvino')}), else CPU",
    )
    parser.add_argument(
        "--frames", type=positive_int, help=f"stop after this many frames (default: all; synthetic: {SYNTHETIC_FRAMES})"
    )
    parser.add_argument(
        "--fps",
        type=positive_number("frame rate"),
        help=f"a folder of frames: the rate they were taken at, frames per second; frame i is stamped i / FPS s, "
        f"which the trackers' velocities and timeouts rest on (default {FOLDER_FPS:g}, said on stderr)",
    )
    parser.add_argument("--out", metavar="DIR", help="also write detections.jsonl, overlay and top-view PNGs here")
    parser.add_argument(
        "--align",
        choices=("none", "sid", "librealsense"),
        default="none",
        help="RealSense sources: 'none' (default) looks depth up sparsely at the keypoints, the "
        "cheapest; 'sid' or 'librealsense' align every depth frame to colour first",
    )
    parser.add_argument(
        "--camera-height",
        type=float,
        default=CameraMount.height,
        help=f"metres above the ground (default {CameraMount.height:g})",
    )
    parser.add_argument(
        "--camera-tilt",
        type=float,
        default=CameraMount.tilt,
        help=f"downward pitch, radians (default {CameraMount.tilt:g})",
    )
    parser.add_argument(
        "--keypoint-threshold",
        type=float,
        default=None,
        help=f"keypoint confidence threshold (default {LiftParams().min_score})",
    )
    parser.add_argument("--no-keypoints", action="store_true", help="leave 3D keypoints out of the JSON lines")
    parser.add_argument(
        "--no-tracking",
        action="store_true",
        help="print each frame's own detections (per-frame person ids, groups of that frame alone) instead of "
        "tracks with stable ids, velocities and standing / walking states (the default, except for a source of "
        "one frame, where there is nothing to track; docs/tracking.md)",
    )
    add_params_file_option(parser, tracking=True)
    add_group_params(parser)
    parser.set_defaults(func=run)


def _source_options(args: argparse.Namespace) -> dict[str, Any]:
    topics = {name: getattr(args, name) for name in BAG_TOPICS}  # refused by open_source for a source without topics
    if args.fps is not None:
        if not is_frame_folder(Path(args.source)):
            raise SourceError(
                f"--fps: only a folder of frames lacks timestamps of its own, and {args.source} is not one"
            )
        return topics | {"fps": args.fps}
    if args.source.startswith("synthetic:"):
        return {"frames": args.frames or SYNTHETIC_FRAMES} | topics
    if args.source == "realsense" or Path(args.source).suffix.lower() in RECORDING_SUFFIXES:
        return {"align": args.align} | topics
    return topics


def _skip_reason(frame: Frame) -> str | None:
    depth = frame.depth
    if depth is None or depth.size == 0:
        return "no depth"
    # One pixel in 256 settles a usual frame (cheaper than the whole image); the whole one only when it has none.
    for view in (depth[::16, ::16], depth):
        if np.any(np.isfinite(view) & (view > 0)):
            return None
    return "no depth"


class _Skipped(NamedTuple):
    frame: Frame
    reason: str


def _posed_frames(source: Iterable[Frame], pipeline: Pipeline) -> Iterator[PosedFrame | _Skipped | FrameReadError]:
    """The first half of each frame's work, which ``run`` has done in a worker thread one frame ahead: read the
    frame and, when it has depth, run the pose model on it. Unreadable frames come as their ``FrameReadError``."""
    for item in frames_or_errors(source):
        if isinstance(item, FrameReadError):
            yield item
            continue
        reason = _skip_reason(item)
        yield _Skipped(item, reason) if reason else pipeline.pose_frame(item)


def camera_view(calibration: Calibration, mount: CameraMount) -> CameraView:
    """The colour camera seen from above: at the world origin, its field of view bounded by the image's left and
    right edges on the principal row."""
    from costmap.render import CameraView

    return CameraView(0.0, 0.0, *camera_fov(calibration, mount))


class PictureRecords(NamedTuple):
    """What a frame's pictures draw, the same records its JSON line holds: per pose detection the person it
    labels in the overlay (None: unlabelled, e.g. a detection no confirmed track took), and the people and groups of
    the top view (world frame, m)."""

    labels: list[Person | None]
    people: list[Person]
    groups: list[Group]


def picture_records(result: FrameResult, tracked: SessionUpdate | None) -> PictureRecords:
    """The frame's own people and groups, or with tracking the confirmed tracks (ids: track ids) and the groups
    the JSON line reports: a detection is labelled with the track that took it."""
    if tracked is None:
        by_id = {p.id: p for p in result.people}
        return PictureRecords(
            [by_id.get(i) for i in range(len(result.detections))], list(result.people), list(result.groups)
        )
    people = [track.as_person() for track in tracked.people]
    by_detection = {t.detection: p for t, p in zip(tracked.people, people, strict=True) if t.detection is not None}
    return PictureRecords(
        [by_detection.get(i) for i in range(len(result.detections))],
        people,
        [group.as_group() for group in tracked.groups],
    )


def _pictures(frame: Frame, result: FrameResult, records: PictureRecords, mount: CameraMount) -> dict[str, bytes]:
    """A frame's overlay and top view of ``records``, encoded as PNG, by file name."""
    from costmap.render import render_costmap

    overlay = draw_detections(frame.color, result.detections, records.labels)
    top = render_costmap(
        Costmap2D.filled(TOP_VIEW),
        records.people,
        records.groups,
        title=f"frame {frame.index}: {plural(len(records.people), 'person', 'people')}, "
        f"{plural(len(records.groups), 'group')}",
        camera=camera_view(frame.calibration, mount),
        scale=6,
    )
    images = {f"overlay_{frame.index:06d}.png": overlay, f"topview_{frame.index:06d}.png": top}
    return {name: cv2.imencode(".png", image)[1].tobytes() for name, image in images.items()}


class _OutFolder:
    """``sid detect --out``: the folder held with its lock (``output_folder_lock``, entered by the caller), an
    earlier run's files cleared, and each frame's line of detections.jsonl written with its pictures, or none."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        cleared = clear_owned(folder, OUTPUTS)  # an earlier run's files, so none is mistaken for this run's
        if cleared:
            print(f"detect: removed {plural(len(cleared), 'file')} of an earlier run from {folder}", file=sys.stderr)
        # Unbuffered: a line that fails half-written is cut off below, and no buffer writes it again at close.
        self._lines = os.open(folder / "detections.jsonl", os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)

    def write(self, line: str, pictures: dict[str, bytes]) -> None:
        """The frame's pictures, then its line; when any of it fails (a full disk) what was written of the frame
        is removed again and the error raised, so detections.jsonl never holds a line whose pictures are missing."""
        written: list[Path] = []
        end = os.lseek(self._lines, 0, os.SEEK_CUR)
        target = self.folder / "detections.jsonl"
        try:
            for name, png in pictures.items():
                target = self.folder / name
                written.append(write_atomically(target, png))
            target = self.folder / "detections.jsonl"
            data = memoryview((line + "\n").encode())
            while data:
                data = data[os.write(self._lines, data) :]
        except BaseException as exc:
            with contextlib.suppress(OSError):
                os.ftruncate(self._lines, end)
                os.lseek(self._lines, end, os.SEEK_SET)
            for path in written:
                path.unlink(missing_ok=True)
            if isinstance(exc, OSError):
                reason = exc.strerror or exc
                raise OSError(f"cannot write {target} ({reason}); the frame's line and pictures are left out") from None
            raise

    def close(self) -> None:
        os.close(self._lines)


def _close_source(source: Iterable[Frame]) -> None:
    """Close ``source`` when it has a ``close`` (cameras, recordings)."""
    close = getattr(source, "close", None)
    if close is not None:
        close()


def _tracked_json(record: dict, tracked: SessionUpdate) -> dict[str, Any]:
    """A frame's JSON line with its people and groups replaced by the tracks (ids: track ids), each person's 3D
    keypoints taken from the detection it matched (null when missed), the trackers' times (ms) added to
    ``timing_ms`` and its ``total``, and ``reset`` when the trackers were."""
    by_id = {person["id"]: person for person in record["people"]}
    with_keypoints = any("keypoints" in person for person in record["people"])
    people = []
    for track in tracked.people:
        person = track.to_json()
        if with_keypoints:
            person["keypoints"] = by_id[track.detection]["keypoints"] if track.detection in by_id else None
        people.append(person)
    record |= {"people": people, "groups": [group.to_json() for group in tracked.groups]}
    timing = record["timing_ms"]
    total = timing.pop("total")  # the frame's stages and the trackers', as SocialStream's total
    timing |= {k: round(v, 3) for k, v in tracked.timing_ms.items()}
    timing["total"] = round(total + sum(tracked.timing_ms.values()), 3)
    if tracked.reset is not None:
        record["reset"] = tracked.reset
    return record


def run(args: argparse.Namespace) -> int:
    if args.out is not None:
        try:
            args.out = check_output_folder(args.out)  # before the model loads and the camera opens
        except OutputFolderError as exc:
            return fail("sid detect", exc)
    try:
        params = params_file_from(args)  # before the model loads and the camera opens, as every check of the options
        group_params = group_params_from(args, params.groups)
        lift = LiftParams() if args.keypoint_threshold is None else LiftParams(min_score=args.keypoint_threshold)
        mount = CameraMount(args.camera_height, args.camera_tilt)
        pose = pose_model(
            args.model, args.source, contract=args.contract, threads=args.threads, providers=args.provider
        )
        source = open_source(args.source, **_source_options(args))
        single = isinstance(source, Sized) and len(source) == 1
        tracking = not (args.no_tracking or single)
        if tracking and args.fps is None and is_frame_folder(Path(args.source)):
            print(
                f"detect: note: a folder's frames carry no time: frame i is stamped i / {FOLDER_FPS:g} s, which the "
                "trackers' velocities rest on (--fps sets the rate they were taken at)",
                file=sys.stderr,
            )
        # With tracking the groups come from the group tracker, so the frame's own grouping would be thrown away.
        pipeline = Pipeline(pose, mount, lift, group_params, group=not tracking)
    except MissingDependencyError as exc:  # --provider openvino without it
        return fail("sid detect", exc)
    except (SourceError, PoseModelError, ValueError, OSError) as exc:
        print(f"detect: {exc}", file=sys.stderr)
        return ExitCode.USAGE

    held = contextlib.ExitStack()  # --out's lock, held until the run ends
    try:
        out = None if args.out is None else _OutFolder(held.enter_context(output_folder_lock(args.out)))
    except OSError as exc:  # another run holds the folder (OutputFolderInUse), or it cannot be written
        held.close()
        _close_source(source)
        return fail("sid detect", exc)

    done = skipped = unreadable = 0  # unreadable: frames whose files could not be read, among the skipped
    unconfirmed = 0  # frames written with people detected but no track reported yet (tracking's people: [])

    def skip(index: int | None, reason: object) -> None:
        nonlocal skipped
        skipped += 1
        print(f"detect: frame {index}: skipped, {reason}", file=sys.stderr)

    interrupted = 0  # the exit code of the signal that stopped the run
    stream = PeopleStream(pipeline, params.tracking) if tracking else None
    totals: list[float] = []
    started = time.perf_counter()
    try:
        # The next frame is read and posed in a worker thread while this one lifts, groups, tracks and writes.
        for item in run_ahead(_posed_frames(source, pipeline)):
            if args.frames is not None and done + skipped >= args.frames:  # unreadable frames count too
                break
            if isinstance(item, FrameReadError):
                skip(item.index, item)
                unreadable += 1
                continue
            frame = item.frame
            if isinstance(item, _Skipped):
                skip(frame.index, item.reason)
                continue
            try:  # the trackers take every frame: tracks age through one without people, which is then skipped
                step = None if stream is None else stream.update_posed(item)
            except TrackingError as exc:
                skip(frame.index, exc)
                continue
            result, tracked = (pipeline.locate(item), None) if step is None else (step.result, step.tracks)
            if not result.people:
                skip(frame.index, "no people")
                continue
            record = result.to_json(keypoints=not args.no_keypoints)
            if tracked is not None:
                record = _tracked_json(record, tracked)
            records = picture_records(result, tracked)
            pictures = _pictures(frame, result, records, mount) if args.out is not None else {}
            line = json.dumps(record)
            with signals_deferred():  # a frame's line and both its pictures, or none of them; and counted
                if out is not None:
                    out.write(line, pictures)
                print(line, flush=True)
                done += 1
                unconfirmed += not record["people"]
                totals.append(record["timing_ms"]["total"])
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM (sid.cli.common.Terminated)
        interrupted = 128 + int(getattr(exc, "signal_number", 2))
        print("detect: interrupted, output flushed", file=sys.stderr)
    except OSError as exc:  # e.g. the disk filled up
        return fail("sid detect", exc)
    except SourceError as exc:
        print(f"detect: source stopped: {exc}", file=sys.stderr)
        return ExitCode.FAILURE
    finally:
        if out is not None:
            out.close()
        held.close()
        _close_source(source)
    seconds = time.perf_counter() - started  # the frames' wall-clock time, start-up (imports, model load) aside
    rate = f" in {seconds:.1f} s ({(done + skipped) / seconds:.1f} frames/s)" if done + skipped else ""
    median = f", median {np.median(totals):.2f} ms per frame" if totals else ""
    waiting = f", {plural(unconfirmed, 'frame')} with no track reported yet (people: [])" if unconfirmed else ""
    summary = f"{plural(done - unconfirmed, 'frame')} with people{waiting}, {skipped} skipped{rate}{median}"
    print(f"detect: {summary}", file=sys.stderr)
    if args.out is not None:  # as every command that writes files says what it wrote; stdout is the JSON lines'
        beside = f" and {done} overlay_*.png, {done} topview_*.png beside it" if done else ""
        print(f"detect: wrote {args.out / 'detections.jsonl'}{beside}", file=sys.stderr)
    if not interrupted and unreadable and unreadable == done + skipped:  # bad input, not a scene without people
        print(f"detect: no frame of the source could be read ({plural(unreadable, 'frame')} tried)", file=sys.stderr)
        return ExitCode.USAGE
    return interrupted
