"""Tracking on synthetic sequences with ground truth: MOTA / IDF1, group F1 with and without tracking, walkers
called a conversation, and costmap flicker (``sid eval tracking``; numbers in docs/tracking.md).

Protocol:

- frames: each built-in sequence (``sid.synthetic.sequence``) rendered at ``fps`` with the default depth and
  keypoint noise, through the per-frame pipeline with ``TruthPose`` (the pose stand-in) and a ``SocialStream``.
- people (py-motmetrics): ground truth = the people whose position lies in the camera's field of view (the
  stream's view cone: the colour image's horizontal opening up to the lifting's max range), hidden or not, since a
  tracker should keep people through occlusions, and those within that range the image shows at its edge;
  hypotheses = the reported tracks (``StreamUpdate.people``) detected in the frame or inside the same cone
  (tracks coasting out of view make no claim about the image). A track within ``match_distance`` of a person may
  match (motmetrics' squared Euclidean distance). MOTA = 1 - (misses + false positives + id switches) /
  ground-truth objects; IDF1: the F1 of identity matches over the sequence.
- groups: per frame, precision and recall of the conversational groups under the F-formation rule
  (``sid.experiments.fformation.score``, tolerance T) against the declared conversations that hold then (all
  members standing), both sides restricted to the ground-truth people above (a group keeps its members the camera
  could see; fewer than two: no group). Without tracking: the pipeline's per-frame groups; with tracking: the
  stream's confirmed conversations. Detections and tracks are identified with true people by a minimum-distance
  assignment within ``match_distance`` (an unidentified member counts as a stranger); frames from
  ``settle_time`` on are scored, the same frames for both.
- walkers called a conversation: frames from ``settle_time`` on in which a reported conversation holds a person
  who is walking.
- flicker: a static layout (people standing; depth and keypoint noise differ every frame, and the detector misses
  each person in a frame with probability ``flicker_miss_rate``); per pair of consecutive frames from
  ``settle_time`` on, the cells of the combined costmap whose cost changes by more than ``flicker_threshold``: the
  per-frame social layer (today's) against the tracked-people layer, both followed by inflation.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import linear_sum_assignment

from costmap.grid import GridSpec
from costmap.layer import LayerInputs
from costmap.layers.social import GROUPS, PEOPLE
from costmap.plugins import CostmapParams, layered_costmap
from sid.checks import check_number, check_whole, repeated
from sid.distribution import MissingDependencyError, install_hint
from sid.errors import InputError
from sid.experiments.fformation import LabelledFrame, format_threshold, score
from sid.experiments.progress import Progress
from sid.perception.frame import Frame
from sid.perception.keypoints import PoseDetection
from sid.perception.mount import CameraMount
from sid.perception.pipeline import Pipeline
from sid.stream import SocialStream
from sid.synthetic.pose import TruthPose
from sid.synthetic.sensor import FrameTruth
from sid.synthetic.sequence import SEQUENCES
from sid.tracking.session import TrackingParams
from sid.tracking.view import ViewCone

__all__ = [
    "MOT_METRICS",
    "MissingDependencyError",
    "TrackingEvalSettings",
    "as_truth_ids",
    "evaluate_tracking",
    "identify",
    "measure_flicker",
    "merged_mot_scores",
    "mot_scores",
    "require_motmetrics",
]


@dataclass(frozen=True)
class TrackingEvalSettings:
    """What ``evaluate_tracking`` runs: sequences (built-in names), frame rate (Hz), noise seed, at most ``frames``
    per sequence (None: all), ``settle_time`` (s) before groups are scored, ``match_distance`` (m), the group
    tolerances T, the flicker layout, frame count, threshold (cost units) and miss rate, the trackers' parameters."""

    sequences: tuple[str, ...] = SEQUENCES
    fps: float = 15.0
    seed: int = 0
    frames: int | None = None
    settle_time: float = 1.0
    match_distance: float = 0.5
    thresholds: tuple[float, ...] = (2 / 3, 1.0)
    flicker_layout: str = "S5"
    flicker_frames: int = 90
    flicker_threshold: int = 50
    flicker_miss_rate: float = 0.1
    tracking: TrackingParams = field(default_factory=TrackingParams)

    def __post_init__(self) -> None:
        check_number("tracking evaluation", "fps", self.fps, low=0, low_open=True)
        check_number("tracking evaluation", "match_distance", self.match_distance, low=0, low_open=True, unit="metres")
        check_number("tracking evaluation", "settle_time", self.settle_time, low=0, unit="seconds")
        check_number("tracking evaluation", "flicker_miss_rate", self.flicker_miss_rate, low=0, high=1, high_open=True)
        for name, low in (("frames", 1), ("flicker_frames", 2)):
            value = getattr(self, name)
            if value is not None:
                check_whole("tracking evaluation", name, value, low=low)
        unknown = [name for name in self.sequences if name not in SEQUENCES]
        if unknown or not self.sequences:
            raise InputError(f"tracking evaluation: unknown sequences {unknown}; known: {', '.join(SEQUENCES)}")
        twice = repeated(list(self.sequences))
        if twice is not None:  # "overall" would count its frames twice
            raise InputError(f"tracking evaluation: sequence {twice} is given twice")


@dataclass
class _FrameLog:
    """What one frame of a sequence gave: truth, raw per-frame results and tracks, as plain arrays and id sets."""

    time: float
    truth: FrameTruth
    view: ViewCone
    raw_positions: np.ndarray
    raw_groups: list[tuple[int, ...]]
    track_ids: list[int]
    track_positions: np.ndarray
    track_visible: np.ndarray
    track_groups: list[tuple[int, ...]]


def require_motmetrics() -> None:
    """Raise MissingDependencyError, with the command that installs it, when py-motmetrics (the people-tracking
    scores of ``sid eval tracking`` and ``sid eval crowd``) is not installed."""
    if importlib.util.find_spec("motmetrics") is None:
        raise MissingDependencyError(
            f"the tracking evaluation needs py-motmetrics: {install_hint('eval')} (or pip install motmetrics)"
        )


def evaluate_tracking(settings: TrackingEvalSettings | None = None, progress: Progress | None = None) -> dict[str, Any]:
    """Every score of the module docstring: ``{"sequences": {name: {...}}, "overall": {...}, "flicker": {...},
    "settings": {...}}``."""
    require_motmetrics()  # fail before any rendering
    settings = settings or TrackingEvalSettings()
    per_sequence: dict[str, Any] = {}
    accumulators, logs_by_name = [], {}
    for name in settings.sequences:
        logs = _run_sequence(name, settings, progress)
        logs_by_name[name] = logs
        accumulator = _accumulate(logs, settings.match_distance)
        accumulators.append(accumulator)
        per_sequence[name] = {"frames": len(logs), **mot_scores([accumulator], [name])[name]}
        per_sequence[name] |= _group_scores(logs, settings)
    overall = mot_scores(accumulators, list(settings.sequences), overall=True)["OVERALL"]
    all_logs = [log for logs in logs_by_name.values() for log in logs]
    overall |= _group_scores(all_logs, settings)
    return {
        "settings": {
            "fps": settings.fps,
            "seed": settings.seed,
            "settle_time_s": settings.settle_time,
            "match_distance_m": settings.match_distance,
        },
        "sequences": per_sequence,
        "overall": overall,
        "flicker": measure_flicker(settings, progress),
    }


def _pipeline(mount: CameraMount, miss_rate: float = 0.0, seed: int = 0) -> Pipeline:
    """The per-frame pipeline on ``TruthPose``, which misses each person with probability ``miss_rate``."""
    truth, rng = TruthPose(), np.random.default_rng(seed)

    def pose(frame: Frame) -> list[PoseDetection]:
        return [d for d in truth(frame) if rng.random() >= miss_rate]

    return Pipeline(pose if miss_rate > 0 else truth, mount)


def _run_sequence(name: str, settings: TrackingEvalSettings, progress: Progress | None) -> list[_FrameLog]:
    from sid.sources.synthetic import SyntheticSource

    source = SyntheticSource(name, frames=settings.frames, seed=settings.seed, fps=settings.fps, shaded_color=False)
    spec = GridSpec.from_size(0.1, (-20.0, -20.0), (40.0, 40.0))  # the costmap is not scored here: coarse
    stream = SocialStream(_pipeline(source.scene.mount), spec, params=settings.tracking)
    logs = []
    for index, frame in enumerate(source):
        update = stream.update(frame)
        people = update.result.people
        logs.append(
            _FrameLog(
                frame.timestamp,
                frame.truth,
                stream.view(frame),
                np.array([[p.x, p.y] for p in people]).reshape(-1, 2),
                [tuple(p_index for p_index, p in enumerate(people) if p.id in g.members) for g in update.result.groups],
                [p.id for p in update.people],
                np.array([[p.x, p.y] for p in update.people]).reshape(-1, 2),
                np.array([p.visible for p in update.people], dtype=bool),
                [g.members for g in update.groups if g.kind == "conversation"],
            )
        )
        if progress:
            progress(index + 1, len(source), name)
    return logs


def _truth_arrays(truth: FrameTruth) -> tuple[list[int], np.ndarray]:
    return [p.id for p in truth.people], np.array([[p.x, p.y] for p in truth.people]).reshape(-1, 2)


def _seen(log: _FrameLog) -> np.ndarray:
    """(N,) bool: which true people count: inside the camera's field of view, or shown in the image (at its edge)
    within the range at which people are detected."""
    positions = _truth_arrays(log.truth)[1]
    view = log.view
    shown = np.array([p.in_view for p in log.truth.people], dtype=bool)
    in_range = np.hypot(positions[:, 0] - view.x, positions[:, 1] - view.y) <= view.max_range
    return view.contains(positions) | (shown & in_range)


def _accumulate(logs: Sequence[_FrameLog], match_distance: float) -> Any:
    import motmetrics

    accumulator = motmetrics.MOTAccumulator(auto_id=True)
    for log in logs:
        ids, positions = _truth_arrays(log.truth)
        seen = _seen(log)
        hyp = log.view.contains(log.track_positions) | log.track_visible
        distances = motmetrics.distances.norm2squared_matrix(
            positions[seen], log.track_positions[hyp], max_d2=match_distance**2
        )
        accumulator.update(
            [i for i, s in zip(ids, seen.tolist(), strict=True) if s],
            [i for i, h in zip(log.track_ids, hyp.tolist(), strict=True) if h],
            distances,
        )
    return accumulator


MOT_METRICS = (
    "mota",
    "motp",
    "idf1",
    "num_switches",
    "num_transfer",
    "num_misses",
    "num_false_positives",
    "num_objects",
)
"""The py-motmetrics metrics every tracking score is made of (``_as_scores`` names them for sid's JSON)."""


def mot_scores(accumulators: list[Any], names: list[str], overall: bool = False) -> dict[str, dict[str, Any]]:
    """py-motmetrics' scores of each accumulator by name, and of all together as ``"OVERALL"`` when ``overall``."""
    import motmetrics

    host = motmetrics.metrics.create()
    table = host.compute_many(accumulators, metrics=list(MOT_METRICS), names=names, generate_overall=overall)
    return {str(name): _as_scores(row) for name, row in table.iterrows()}


def merged_mot_scores(parts: list[Any]) -> dict[str, Any]:
    """py-motmetrics' scores of one sequence scored in independent parts (accumulators over disjoint true people
    and tracks, no pair of them ever within the match distance), merged by motmetrics' overall rules: the same as
    one accumulator over the whole. A part without a match adds no distance to MOTP (motmetrics' merge would carry
    its undefined MOTP, 0 / 0, into the total)."""
    import motmetrics

    host = motmetrics.metrics.create()
    partials = [
        host.compute(part, metrics=list(MOT_METRICS), return_dataframe=False, return_cached=True) for part in parts
    ]
    for partial in partials:
        if partial["num_detections"] == 0:
            partial["motp"] = 0.0
    return _as_scores(host.compute_overall(partials, metrics=list(MOT_METRICS), return_dataframe=False))


def _as_scores(values: Any) -> dict[str, Any]:
    """One motmetrics result (a table row or a dict of ``MOT_METRICS``) as sid's tracking scores."""
    return {
        "mota": float(values["mota"]),
        "idf1": float(values["idf1"]),
        "motp_m": float(np.sqrt(values["motp"])) if np.isfinite(values["motp"]) else None,  # of squared distances
        "id_switches": int(values["num_switches"]),
        "id_transfers": int(values["num_transfer"]),  # a track that moved on to another person
        "misses": int(values["num_misses"]),
        "false_positives": int(values["num_false_positives"]),
        "objects": int(values["num_objects"]),
    }


def identify(positions: np.ndarray, truth_ids: list[int], truth_positions: np.ndarray, gate: float) -> list[int | None]:
    """The true person id of each of ``positions`` (N, 2) by minimum total distance within ``gate`` (m)."""
    out: list[int | None] = [None] * len(positions)
    if not len(positions) or not len(truth_positions):
        return out
    distance = np.linalg.norm(positions[:, None] - truth_positions[None], axis=2)
    rows, cols = linear_sum_assignment(np.where(distance <= gate, distance, 1e9))
    for row, col in zip(rows.tolist(), cols.tolist(), strict=True):
        if distance[row, col] <= gate:
            out[row] = truth_ids[col]
    return out


def as_truth_ids(groups: list[tuple[int, ...]], key: list[int], identity: list[int | None]) -> list[frozenset[int]]:
    """Groups of ``key`` ids (detection indexes or track ids) as groups of true ids; unidentified members are
    kept as distinct negative ids (they count against the group, as a stranger would)."""
    lookup = {k: (i if i is not None else -1 - n) for n, (k, i) in enumerate(zip(key, identity, strict=True))}
    return [frozenset(lookup[m] for m in g) for g in groups]


def _group_scores(logs: Sequence[_FrameLog], settings: TrackingEvalSettings) -> dict[str, Any]:
    scored = [log for log in logs if log.time >= settings.settle_time]
    if not scored:
        return {}
    frames, raw, tracked = [], [], []
    walkers_raw = walkers_tracked = 0
    for log in scored:
        ids, positions = _truth_arrays(log.truth)
        hidden = {i for i, seen in zip(ids, _seen(log).tolist(), strict=True) if not seen}
        walking = {p.id for p in log.truth.people if p.walking}
        frames.append(LabelledFrame("", log.time, [], [frozenset(g.members) - hidden for g in log.truth.groups]))
        raw_identity = identify(log.raw_positions, ids, positions, settings.match_distance)
        raw_groups = [g - hidden for g in as_truth_ids(log.raw_groups, list(range(len(raw_identity))), raw_identity)]
        track_identity = identify(log.track_positions, ids, positions, settings.match_distance)
        track_groups = [g - hidden for g in as_truth_ids(log.track_groups, log.track_ids, track_identity)]
        raw.append(raw_groups)
        tracked.append(track_groups)
        walkers_raw += any(g & walking for g in raw_groups)
        walkers_tracked += any(g & walking for g in track_groups)
    out: dict[str, Any] = {"group_frames": len(frames)}
    for threshold in settings.thresholds:
        t = format_threshold(threshold)
        out[f"group_f1_T{t}"] = {
            "without_tracking": score(frames, raw, threshold).to_dict(),
            "with_tracking": score(frames, tracked, threshold).to_dict(),
        }
    out["frames_walkers_in_a_conversation"] = {"without_tracking": walkers_raw, "with_tracking": walkers_tracked}
    return out


def measure_flicker(settings: TrackingEvalSettings | None = None, progress: Progress | None = None) -> dict[str, Any]:
    """Cells changing by more than the threshold between consecutive frames of a static layout: the per-frame
    social layer against the tracked-people layer (module docstring)."""
    from sid.sources.synthetic import SyntheticSource

    settings = settings or TrackingEvalSettings()
    source = SyntheticSource(
        settings.flicker_layout, frames=settings.flicker_frames, seed=settings.seed, fps=settings.fps,
        shaded_color=False,
    )  # fmt: skip
    spec = GridSpec.from_size(0.05, (-0.5, -3.5), (7.5, 7.0))  # 7 m ahead of the camera, 3.5 m each side
    per_frame = layered_costmap(spec, CostmapParams(plugins=("social", "inflation")))
    pipeline = _pipeline(source.scene.mount, settings.flicker_miss_rate, settings.seed)
    stream = SocialStream(pipeline, spec, CostmapParams(plugins=("tracked_people", "inflation")), settings.tracking)
    changed: dict[str, list[int]] = {"per_frame": [], "tracked": []}
    previous: dict[str, np.ndarray] = {}
    for index, frame in enumerate(source):
        update = stream.update(frame)
        per_frame.update(LayerInputs({PEOPLE: update.result.people, GROUPS: update.result.groups}))
        for name, grid in (("per_frame", per_frame.master.costs), ("tracked", update.costmap.costs)):
            grid = grid.astype(np.int16)
            if name in previous and index * 1.0 / settings.fps >= settings.settle_time:
                changed[name].append(int(np.count_nonzero(np.abs(grid - previous[name]) > settings.flicker_threshold)))
            previous[name] = grid
        if progress:
            progress(index + 1, len(source), f"flicker {settings.flicker_layout}")
    return {
        "layout": settings.flicker_layout,
        "frames": len(source),
        "threshold": settings.flicker_threshold,
        "miss_rate": settings.flicker_miss_rate,
        "pairs_scored": len(changed["tracked"]),
        **{
            name: {
                "changed_cells_total": int(sum(counts)),
                "changed_cells_per_frame_mean": float(np.mean(counts)) if counts else 0.0,
                "frames_with_changes": int(sum(c > 0 for c in counts)),
            }
            for name, counts in changed.items()
        },
    }
