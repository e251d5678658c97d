"""People and walking groups over time on real pedestrian trajectories (``sid eval crowd``; docs/tracking.md).

Protocol:

- detections: each set replayed by ``sid.experiments.trajectories.replay`` (annotation times or a camera's rate,
  seeded 0.1 m noise, 10 % misses, optionally a field of view), fed to ``TrackingSession.track``: the people tracker
  and then the group tracker, the classes ``sid track`` runs. The tracker is told where the detector looks: the
  robot's view when one is set, else the area the set's camera covered (the convex hull of all annotated
  positions), so that a track coasting out of the scene is not counted as a person in it. The coherent-motion
  reference (``sid.tracking.coherent``) runs on the same tracks.
- people (py-motmetrics): ground truth = the people present (inside the robot's view when one is set);
  hypotheses = the confirmed tracks detected in the frame or inside the view that ``TrackingSession`` reports
  (``split_reported``: detected or missed in the view for at most ``report_timeout``, or a member of a group with
  such a member). A track within ``match_distance`` may match. MOTA, IDF1, identity switches (also per 100 true
  tracks). People and tracks never within ``match_distance`` of each other are scored in separate motmetrics
  accumulators and merged (``MOT_PART_IDS``).
- groups: each frame's tracks are identified with true people by minimum total distance within ``match_distance``
  (an unidentified member is a stranger). Truth = the annotated groups holding among the people present (two or
  more members there). G-MITRE (``sid.experiments.gmitre``): link counts over the people present, everyone not
  in a group alone, pooled over all frames. Group matching at T = 2/3 and T = 1 (``fformation.frame_matches``): the
  true groups found, groups reported and true groups, summed over all frames (frames without any group on either
  side then count for nothing).
- ``cross_validate``: leave one set out, in three stages: the people tracker's parameters by the best mean IDF1 on
  the others, the group trackers' by the best mean G-MITRE F1, then ``report_timeout`` by the best mean IDF1.
"""

from __future__ import annotations

import dataclasses
import itertools
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse
import scipy.sparse.csgraph

from sid.checks import check_limit
from sid.experiments.fformation import format_threshold, frame_matches
from sid.experiments.gmitre import LinkCounts, gmitre_counts
from sid.experiments.progress import Progress
from sid.experiments.synthetic_tracking import as_truth_ids, identify, merged_mot_scores, require_motmetrics
from sid.experiments.trajectories import ReplaySettings, TrajectoryError, TrajectorySet, replay, replay_length
from sid.experiments.workers import map_in_workers
from sid.tracking.coherent import CoherentMotion, CoherentMotionParams
from sid.tracking.groups import GroupTracker, GroupTrackerParams
from sid.tracking.records import TrackedPerson
from sid.tracking.session import TrackingParams, TrackingSession, split_reported
from sid.tracking.tracker import TimeGapWarning, TrackerParams
from sid.tracking.view import View, scene_view

__all__ = [
    "CrowdSettings",
    "DEFAULT_GRID",
    "EVALUATION_PASSES",
    "MOT_PART_IDS",
    "TrackLog",
    "cross_validate",
    "evaluate_crowd",
    "find_coherent_groups",
    "find_groups",
    "record_tracks",
    "replay_view",
    "reported_log",
    "score_groups",
    "score_people",
]

DEFAULT_GRID: dict[str, dict[str, tuple[float, ...]]] = {
    "tracker": {
        "measurement_sigma": (0.1, 0.15, 0.2),
        "acceleration_sigma": (0.2, 0.3, 0.5),
        "max_gate": (1.0, 1.5),
        "timeout": (1.0, 1.5, 2.0),
    },
    "groups": {
        "walk_distance": (1.2, 1.5, 2.0),
        "walk_velocity_difference": (0.3, 0.4, 0.5, 0.6, 0.8, 1.0),
        "moving_speed": (0.2, 0.3, 0.4),
        "walk_confirm_hits": (1, 3),
        "walk_window": (2.0, 3.0, 4.0),
    },
    "coherent": {"distance": (1.0, 1.5, 2.0), "velocity_difference": (0.3, 0.4, 0.5, 0.6), "share": (0.4, 0.6, 0.8)},
    "reporting": {"report_timeout": (0.2, 0.4, 0.6, 0.8, 1.5)},
}
"""What ``cross_validate`` chooses among: the people tracker's, the group tracker's and the reference's parameters,
and how long a missed track is reported (``TrackingParams.report_timeout``; 1.5 s, the default tracker's timeout:
every track it keeps is reported)."""


@dataclass(frozen=True)
class CrowdSettings:
    """What ``evaluate_crowd`` runs: the replay, the trackers' and the reference's parameters, the matching
    distance (m) and the group tolerances T."""

    replay: ReplaySettings = field(default_factory=ReplaySettings)
    tracking: TrackingParams = field(default_factory=TrackingParams)
    coherent: CoherentMotionParams = field(default_factory=CoherentMotionParams)
    match_distance: float = 0.5
    thresholds: tuple[float, ...] = (2 / 3, 1.0)


@dataclass(frozen=True, eq=False)
class TrackLog:
    """One replayed set through the people tracker: per frame the time (s), the truth (ids, (K, 2) positions m),
    the confirmed tracks (``TrackedPerson``s) detected or in view (``tracks``: the tracker's own hypotheses; those
    reported once ``reported_log`` has kept them), and every confirmed track (``confirmed``: the group tracker's
    input, as in ``TrackingSession``; None: ``tracks``)."""

    name: str
    times: list[float]
    truth_ids: list[np.ndarray]
    truth_positions: list[np.ndarray]
    tracks: list[list[TrackedPerson]]
    confirmed: list[list[TrackedPerson]] | None = None

    @property
    def group_input(self) -> list[list[TrackedPerson]]:
        """Per frame, the tracks the group tracker sees: every confirmed one."""
        return self.tracks if self.confirmed is None else self.confirmed

    def track_positions(self, frame: int) -> np.ndarray:
        return np.array([[p.x, p.y] for p in self.tracks[frame]]).reshape(-1, 2)


def record_tracks(
    trajectories: TrajectorySet, settings: CrowdSettings | None = None, progress: Progress | None = None
) -> TrackLog:
    """Replay ``trajectories`` through the people tracker (``TrackingSession.track``, groups left to the caller)."""
    settings = settings or CrowdSettings()
    session = TrackingSession(settings.tracking)
    confirmed: list[list[TrackedPerson]] = []
    log = TrackLog(trajectories.name, [], [], [], [], confirmed)
    total = replay_length(trajectories, settings.replay.rate)
    view = replay_view(trajectories, settings.replay)
    for k, frame in enumerate(replay(trajectories, settings.replay)):
        with warnings.catch_warnings():  # the sets' annotations pause for seconds: gaps of the data, not of units
            warnings.simplefilter("ignore", TimeGapWarning)
            people = session.people.update(frame.detections, frame.timestamp, view)
        log.times.append(frame.timestamp)
        log.truth_ids.append(frame.truth_ids)
        log.truth_positions.append(frame.truth_positions)
        log.tracks.append([p for p in people if p.visible or p.in_view])
        confirmed.append(people)
        if progress is not None:
            progress(k + 1, total, trajectories.name)
    if not any(len(ids) for ids in log.truth_ids):
        raise TrajectoryError(f"{trajectories.name}: nobody annotated is ever inside the view: nothing to score")
    return log


def replay_view(trajectories: TrajectorySet, replay_settings: ReplaySettings) -> View:
    """Where the detector looks in a replay of ``trajectories``: the settings' view, else the scene's (the convex
    hull of every annotated position). TrajectoryError naming the set when the positions span no area (no scene to
    draw) or the replay would take more frames than the ``replay_frames`` limit (a long gap in the annotations at
    a high rate); ``evaluate_crowd`` and ``cross_validate`` check every set with it before any work."""
    frames = replay_length(trajectories, replay_settings.rate)
    if replay_settings.rate is not None:
        span = float(trajectories.times[-1] - trajectories.times[0])
        detail = f"{span:g} s at {replay_settings.rate:g} Hz = "
        check_limit(f"{trajectories.name}: replay", frames, "replay_frames", "frames", detail)
    if replay_settings.view is not None:
        return replay_settings.view
    try:
        return scene_view(np.concatenate(trajectories.positions))
    except ValueError as exc:
        raise TrajectoryError(f"{trajectories.name}: {exc}; set the robot's view instead (--view)") from None


def reported_log(
    log: TrackLog, groups: Sequence[Sequence[frozenset[int]]], report_timeout: float
) -> tuple[TrackLog, list[list[frozenset[int]]]]:
    """``log`` with, in each frame, only the tracks detected or in view that ``TrackingSession`` reports beside
    ``groups`` (that frame's groups of every confirmed track, member track ids: ``find_groups``), and the groups it
    reports (``sid.tracking.session.split_reported``)."""
    tracks, shown = [], []
    for people, found in zip(log.group_input, groups, strict=True):
        reported, _, kept = split_reported(people, found, report_timeout)
        tracks.append([p for p in reported if p.visible or p.in_view])
        shown.append([group for group, keep in zip(found, kept, strict=True) if keep])
    return TrackLog(log.name, log.times, log.truth_ids, log.truth_positions, tracks, log.confirmed), shown


def score_groups(
    trajectories: TrajectorySet,
    log: TrackLog,
    groups: Sequence[Sequence[frozenset[int]]],
    settings: CrowdSettings | None = None,
    progress: Progress | None = None,
) -> dict[str, Any]:
    """G-MITRE and per-frame matching of ``groups`` (per frame of ``log``: member track ids) against the truth,
    each group cut to its members among the frame's tracks (two or more; those out of view are no hypotheses);
    ``progress`` after each frame."""
    settings = settings or CrowdSettings()
    links = LinkCounts()
    matches = {t: np.zeros(3, dtype=np.int64) for t in settings.thresholds}
    for k, found in enumerate(groups):
        if progress is not None:
            progress(k + 1, len(groups), log.name)
        ids = log.truth_ids[k].tolist()
        present = set(ids)
        truth = trajectories.truth_groups(present)
        track_ids = [p.id for p in log.tracks[k]]
        identity = identify(log.track_positions(k), ids, log.truth_positions[k], settings.match_distance)
        scored = set(track_ids)  # a group's members out of view are not scored, as the truth's absent members
        seen = [tuple(sorted(g & scored)) for g in found if len(g & scored) >= 2]
        as_truth = as_truth_ids(seen, track_ids, identity)
        in_scene = [g & present for g in as_truth]
        grouped = set().union(*truth)
        found_grouped = set().union(*in_scene) if in_scene else set()
        links += gmitre_counts(
            truth + [{i} for i in present - grouped],
            [g for g in in_scene if g] + [{i} for i in present - found_grouped],
        )
        for threshold in settings.thresholds:
            matches[threshold] += frame_matches(as_truth, truth, threshold)
    out: dict[str, Any] = {
        "gmitre": {"precision": links.precision, "recall": links.recall, "f1": links.f1},
    }
    for threshold, (hits, found_count, true_count) in matches.items():
        precision = hits / found_count if found_count else 1.0
        recall = hits / true_count if true_count else 1.0
        f1 = 2 * precision * recall / (precision + recall) if precision + recall > 0 else 0.0
        out[f"groups_T{format_threshold(threshold)}"] = {
            "precision": precision,
            "recall": recall,
            "f1": f1,
            "true_groups": int(true_count),
            "found_groups": int(found_count),
        }
    return out


def find_groups(
    log: TrackLog, params: GroupTrackerParams, progress: Progress | None = None
) -> list[list[frozenset[int]]]:
    """Per frame of ``log``: the group tracker's confirmed groups (any kind) on every confirmed track, as
    ``TrackingSession`` runs it, as member track ids; ``progress`` after each frame."""
    tracker = GroupTracker(params)

    def update(people: list[TrackedPerson], timestamp: float) -> list[frozenset[int]]:
        return [frozenset(g.members) for g in tracker.update(people, timestamp)]

    return _per_frame(log, log.group_input, update, progress)


def find_coherent_groups(
    log: TrackLog, params: CoherentMotionParams, progress: Progress | None = None
) -> list[list[frozenset[int]]]:
    """Per frame of ``log``: the coherent-motion reference's groups, as member track ids; ``progress`` after each
    frame."""
    return _per_frame(log, log.tracks, CoherentMotion(params).update, progress)


def _per_frame(
    log: TrackLog,
    tracks: Sequence[list[TrackedPerson]],
    update: Callable[[list[TrackedPerson], float], list[frozenset[int]]],
    progress: Progress | None,
) -> list[list[frozenset[int]]]:
    """``update(tracks[k], timestamp)`` on every frame k of ``log`` in order, its answers; ``progress`` after each."""
    found = []
    for k, (t, people) in enumerate(zip(log.times, tracks, strict=True)):
        found.append(update(people, t))
        if progress is not None:
            progress(k + 1, len(log.times), log.name)
    return found


def score_people(log: TrackLog, match_distance: float, progress: Progress | None = None) -> dict[str, Any]:
    """MOTA, IDF1, identity switches (also per 100 true tracks: the distinct annotated people scored, those ever
    inside the view) and the other motmetrics counts of ``log``; ``progress`` after each frame matched."""
    people = merged_mot_scores(_accumulate(log, match_distance, progress))
    true_tracks = len(np.unique(np.concatenate(log.truth_ids)))
    people["true_tracks"] = true_tracks
    people["id_switches_per_100_tracks"] = 100 * people["id_switches"] / max(true_tracks, 1)
    return people


def evaluate_crowd(
    sets: Sequence[TrajectorySet], settings: CrowdSettings | None = None, progress: Progress | None = None
) -> dict[str, Any]:
    """Tracking and group scores of every set, sid's group tracker beside the coherent-motion reference;
    ``progress`` over each set's six passes through its frames (``EVALUATION_PASSES``), one count per set."""
    require_motmetrics()
    settings = settings or CrowdSettings()
    for trajectories in sets:  # every set's replay checked before the first runs
        replay_view(trajectories, settings.replay)
    out: dict[str, Any] = {"settings": _settings_json(settings), "sets": {}}
    for trajectories in sets:
        passes = [_pass(progress, k, trajectories.name) for k in range(len(EVALUATION_PASSES))]
        log = record_tracks(trajectories, settings, passes[0])
        found = find_groups(log, settings.tracking.groups, passes[1])
        shown, reported = reported_log(log, found, settings.tracking.report_timeout)
        people = score_people(shown, settings.match_distance, passes[2])
        groups = score_groups(trajectories, shown, reported, settings, passes[3])
        reference = find_coherent_groups(log, settings.coherent, passes[4])
        out["sets"][trajectories.name] = {
            "frames": len(log.times),
            "notes": list(trajectories.notes),
            "people": people,
            "groups": groups,
            "coherent_motion": score_groups(trajectories, log, reference, settings, passes[5]),
        }
    return out


EVALUATION_PASSES = (
    "tracking",
    "group tracker",
    "matching people",
    "scoring groups",
    "reference groups",
    "scoring the reference",
)
"""What ``evaluate_crowd`` does with each set, one pass over its frames each, as its progress names them."""


def _pass(progress: Progress | None, index: int, name: str) -> Progress | None:
    """``progress`` for pass ``index`` of ``EVALUATION_PASSES`` over set ``name``: counting on from the passes
    before it, out of all of them."""
    if progress is None:
        return None
    report = progress  # bound here for the closure's type
    stages = len(EVALUATION_PASSES)

    def step(done: int, total: int, what: str) -> None:
        report(index * total + done, stages * total, f"{name}: {EVALUATION_PASSES[index]}")

    return step


def cross_validate(
    sets: Sequence[TrajectorySet],
    settings: CrowdSettings | None = None,
    grid: Mapping[str, Mapping[str, Sequence[float]]] | None = None,
    progress: Progress | None = None,
    workers: int = 1,
) -> dict[str, Any]:
    """Leave one set out, in three stages per held-out set: the people tracker's grid point (``grid["tracker"]``)
    with the best mean IDF1 on the other sets (of every confirmed track detected or in view: the tracker's own);
    then, on that tracker's tracks, the group tracker's (``grid["groups"]``) and the reference's
    (``grid["coherent"]``) points with the best mean G-MITRE F1 on the other sets; then, beside the chosen group
    tracker's groups, the ``report_timeout`` (``grid["reporting"]``) with the best mean IDF1 of the tracks reported;
    each scored on the held-out set. Ties go to the first point in the grid's order. The first two stages' grid
    points are scored in ``workers`` processes (``sid.experiments.workers``; the same result as one)."""
    require_motmetrics()
    settings = settings or CrowdSettings()
    for trajectories in sets:  # every set's replay checked before the first runs
        replay_view(trajectories, settings.replay)
    grid = grid if grid is not None else DEFAULT_GRID
    trackers = _points(settings.tracking.tracker, grid.get("tracker", {}))
    candidates = [
        (which, params)
        for which, base in (("groups", settings.tracking.groups), ("coherent", settings.coherent))
        for params in _points(base, grid.get(which, {}))
    ]
    idf1 = np.array(map_in_workers(_tracker_idf1, (sets, settings), trackers, workers, progress, "tracker points"))
    group_f1: dict[int, np.ndarray] = {}  # tracker row -> (candidates, sets)
    tracker_logs: dict[int, list[TrackLog]] = {}
    folds = []
    for col, trajectories in enumerate(sets):
        train = np.delete(idf1, col, axis=1).mean(axis=1)
        row = int(np.argmax(train))
        if row not in group_f1:  # the chosen tracker's tracks, replayed again (seeded: the same) for its groups
            logs = tracker_logs[row] = [record_tracks(s, _with_tracker(settings, trackers[row])) for s in sets]
            what = f"group points on tracker {row + 1}"
            group_f1[row] = np.array(
                map_in_workers(_group_f1, (sets, logs, settings), candidates, workers, progress, what)
            )
        fold: dict[str, Any] = {
            "held_out": trajectories.name,
            "tracker": {
                "chosen": _changed(trackers[row], grid.get("tracker", {})),
                "train_idf1": float(train[row]),
                "held_out_idf1": float(idf1[row, col]),
            },
        }
        chosen: dict[str, Any] = {}
        for which in ("groups", "coherent"):
            rows = [k for k, (kind, _) in enumerate(candidates) if kind == which]
            table = group_f1[row][rows]
            others = np.delete(table, col, axis=1).mean(axis=1)
            best = int(np.argmax(others))
            chosen[which] = candidates[rows[best]][1]
            fold[which] = {
                "chosen": _changed(candidates[rows[best]][1], grid.get(which, {})),
                "train_f1": float(others[best]),
                "held_out_f1": float(table[best, col]),
            }
        fold["reporting"] = _choose_reporting(
            tracker_logs[row], settings, chosen["groups"], grid.get("reporting", {}), col, progress
        )
        folds.append(fold)
    return {"folds": folds, "grid": {k: {n: list(v) for n, v in g.items()} for k, g in grid.items()}}


def _tracker_idf1(shared: tuple[Sequence[TrajectorySet], CrowdSettings], tracker: TrackerParams) -> list[float]:
    """IDF1 of the people tracker with ``tracker``'s parameters on each set (``cross_validate``'s first stage)."""
    sets, settings = shared
    trial = _with_tracker(settings, tracker)
    return [score_people(record_tracks(s, trial), settings.match_distance)["idf1"] for s in sets]


def _group_f1(
    shared: tuple[Sequence[TrajectorySet], Sequence[TrackLog], CrowdSettings],
    candidate: tuple[str, GroupTrackerParams | CoherentMotionParams],
) -> list[float]:
    """G-MITRE F1 on each set of the group tracker's or the reference's groups with the ``candidate``'s parameters,
    on the tracks ``shared`` holds (``cross_validate``'s second stage)."""
    sets, logs, settings = shared
    params = candidate[1]
    out = []
    for trajectories, log in zip(sets, logs, strict=True):
        if isinstance(params, GroupTrackerParams):
            scored, found = reported_log(log, find_groups(log, params), settings.tracking.report_timeout)
        else:  # as evaluate_crowd scores them
            scored, found = log, find_coherent_groups(log, params)
        out.append(score_groups(trajectories, scored, found, settings)["gmitre"]["f1"])
    return out


def _choose_reporting(
    logs: Sequence[TrackLog],
    settings: CrowdSettings,
    params: GroupTrackerParams,
    axes: Mapping[str, Sequence[float]],
    held_out: int,
    progress: Progress | None = None,
) -> dict[str, Any]:
    """``cross_validate``'s third stage for the set ``held_out`` (an index of ``logs``): the point of ``axes`` (fields
    of ``TrackingParams``) whose tracks reported beside the groups of the group tracker with ``params`` have the best
    mean IDF1 on the other sets; that IDF1 and the held-out set's. ``progress`` after each point."""
    points = _points(settings.tracking, axes)
    groups = [find_groups(log, params) for log in logs]
    idf1 = np.zeros((len(points), len(logs)))
    for k, point in enumerate(points):
        for col, (log, found) in enumerate(zip(logs, groups, strict=True)):
            idf1[k, col] = score_people(reported_log(log, found, point.report_timeout)[0], settings.match_distance)[
                "idf1"
            ]
        if progress is not None:
            progress(k + 1, len(points), f"reporting points, {logs[held_out].name} held out")
    others = np.delete(idf1, held_out, axis=1).mean(axis=1)
    best = int(np.argmax(others))
    return {
        "chosen": _changed(points[best], axes),
        "train_idf1": float(others[best]),
        "held_out_idf1": float(idf1[best, held_out]),
    }


def _points(base: Any, axes: Mapping[str, Sequence[float]]) -> list[Any]:
    names = list(axes)
    combos = itertools.product(*axes.values())
    return [dataclasses.replace(base, **dict(zip(names, values, strict=True))) for values in combos]


def _changed(params: Any, axes: Mapping[str, Sequence[float]]) -> dict[str, float]:
    return {name: getattr(params, name) for name in axes}


def _with_tracker(settings: CrowdSettings, tracker: TrackerParams) -> CrowdSettings:
    return dataclasses.replace(settings, tracking=dataclasses.replace(settings.tracking, tracker=tracker))


MOT_PART_IDS = 500
"""The most ids (true people and tracks together) one motmetrics accumulator of ``score_people`` holds, unless
people and tracks linked by a match candidate are more: motmetrics matches identities for IDF1 on a dense square of
every id an accumulator holds, so one accumulator over a long, dense set takes memory that grows with the square of
its ids (gigabytes at 5 000 people)."""


def _accumulate(log: TrackLog, match_distance: float, progress: Progress | None = None) -> list[Any]:
    """motmetrics accumulators over ``log`` in independent parts: true people and tracks linked, in any frame, by a
    distance within ``match_distance`` (a match candidate) stay in one part, and parts are filled in the order
    people appear up to ``MOT_PART_IDS`` ids. No match, switch or identity pairing crosses parts, so their merged
    scores are those of one accumulator (``merged_mot_scores``). ``progress`` after each frame."""
    import motmetrics

    max_d2 = match_distance**2
    truth_node: dict[int, int] = {}
    track_node: dict[int, int] = {}
    edges: list[np.ndarray] = []
    for k in range(len(log.times)):  # number people and tracks in order of appearance, collect the candidates
        rows = np.array([truth_node.setdefault(int(i), len(truth_node) + len(track_node)) for i in log.truth_ids[k]])
        cols = np.array([track_node.setdefault(p.id, len(truth_node) + len(track_node)) for p in log.tracks[k]])
        pairs = np.argwhere(np.isfinite(_distances(log, k, max_d2)))
        edges.append(np.stack([rows[pairs[:, 0]], cols[pairs[:, 1]]], axis=1).reshape(-1, 2))
    part = _parts(len(truth_node) + len(track_node), np.concatenate(edges) if edges else np.empty((0, 2), int))
    accumulators = [motmetrics.MOTAccumulator(auto_id=True) for _ in range(int(part.max(initial=-1)) + 1)]
    for k in range(len(log.times)):
        truth_ids = log.truth_ids[k].tolist()
        track_ids = [p.id for p in log.tracks[k]]
        row_part = part[[truth_node[int(i)] for i in truth_ids]].reshape(-1)
        col_part = part[[track_node[i] for i in track_ids]].reshape(-1)
        distances = _distances(log, k, max_d2)  # again, not kept from the first pass: (truth, tracks) per frame
        for index in np.unique(np.concatenate([row_part, col_part])).tolist():
            rows, cols = row_part == index, col_part == index
            accumulators[index].update(
                [i for i, r in zip(truth_ids, rows.tolist(), strict=True) if r],
                [i for i, c in zip(track_ids, cols.tolist(), strict=True) if c],
                distances[np.ix_(rows, cols)],
            )
        if progress is not None:
            progress(k + 1, len(log.times), log.name)
    return accumulators


def _distances(log: TrackLog, frame: int, max_d2: float) -> np.ndarray:
    """(truth, tracks) squared distances (m^2) of ``frame``, NaN beyond ``max_d2``: motmetrics' match candidates."""
    import motmetrics

    return np.asarray(
        motmetrics.distances.norm2squared_matrix(log.truth_positions[frame], log.track_positions(frame), max_d2=max_d2)
    ).reshape(len(log.truth_ids[frame]), len(log.tracks[frame]))


def _parts(nodes: int, edges: np.ndarray) -> np.ndarray:
    """(nodes,) part index of each node: the connected components of ``edges`` ((E, 2) node pairs), taken in the
    order of their first node and packed into parts of at most ``MOT_PART_IDS`` nodes (a larger component alone)."""
    graph = scipy.sparse.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(nodes, nodes))
    _, component = scipy.sparse.csgraph.connected_components(graph, directed=False)
    first = np.full(component.max(initial=-1) + 1, nodes)
    np.minimum.at(first, component, np.arange(nodes))
    sizes = np.bincount(component, minlength=len(first))
    part_of_component = np.empty(len(first), dtype=np.int64)
    part, filled = -1, MOT_PART_IDS
    for c in np.argsort(first, kind="stable").tolist():
        if filled + sizes[c] > MOT_PART_IDS:
            part, filled = part + 1, 0
        part_of_component[c] = part
        filled += int(sizes[c])
    return part_of_component[component]


def _settings_json(settings: CrowdSettings) -> dict[str, Any]:
    replay_settings = dataclasses.asdict(settings.replay)
    return {
        "replay": replay_settings,
        "tracker": dataclasses.asdict(settings.tracking.tracker),
        "group_tracker": dataclasses.asdict(settings.tracking.groups),
        "report_timeout": settings.tracking.report_timeout,
        "coherent_motion": dataclasses.asdict(settings.coherent),
        "match_distance": settings.match_distance,
        "thresholds": list(settings.thresholds),
    }
