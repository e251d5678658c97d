"""F-formation group benchmarks: load the Verona datasets' ``.mat`` files and score a group detector on them.

Format (``features.mat`` / ``groundtruth.mat``, MATLAB v5, one folder per sequence): ``features{t}`` is an N x 4
array ``[id, x, y, theta]`` per frame with ``timestamp(t)``; ``GTgroups{t}`` lists the member ids of each group at
``GTtimestamp(t)``. x, y are ground-plane coordinates (centimetres in the public sets: use ``scale=0.01``), theta
is the facing yaw in radians in the same frame. A dataset is a folder holding ``features.mat`` (one sequence) or
sub-folders that do (sequences pooled frame by frame).

Scoring (the protocol of this literature; its source: docs/parameters.md): only frames with ground truth are scored,
groups of one are dropped on both sides; a truth group is found when some detected group G has
|G & GT| / max(|G|, |GT|) >= T; per frame TP = found truth groups, FP = detections - TP, FN = truth - TP,
precision = TP / (TP + FP), recall = TP / (TP + FN) (nothing detected and no truth: P = R = 1; truth but nothing
detected: P = 1, R = 0; detections but no truth: P = 0, R = 1); a dataset scores the mean precision and mean recall
over its frames, and F1 = 2PR / (P + R).

``cross_validate`` chooses detector parameters leaving one dataset out at a time (docs/groups.md).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import scipy.io

from sid.checks import check_number
from sid.perception.groups import GroupParams, detect_groups
from sid.perception.people import Person

DEFAULT_THRESHOLDS: tuple[float, ...] = (2 / 3, 1.0)


@dataclass
class LabelledFrame:
    """One scored frame: the people (world frame, metres after scaling) and the true groups (member ids)."""

    sequence: str
    timestamp: float
    people: list[Person]
    truth: list[frozenset[int]]


@dataclass
class Score:
    """Mean precision and recall over frames, their F1, and the number of frames scored."""

    precision: float
    recall: float
    f1: float
    frames: int

    def to_dict(self) -> dict[str, float | int]:
        return {"precision": self.precision, "recall": self.recall, "f1": self.f1, "frames": self.frames}


def load_sequence(folder: str | Path, scale: float = 1.0) -> list[LabelledFrame]:
    """The ground-truth frames of one sequence folder (``features.mat`` + ``groundtruth.mat``).

    Positions are multiplied by ``scale`` (0.01 turns the datasets' centimetres into metres). A NaN yaw becomes
    an unknown facing (theta None). Raises ValueError naming the file for anything malformed.
    """
    folder = Path(folder)
    check_number("fformation", "scale", scale, low=0, low_open=True)
    features_path, truth_path = folder / "features.mat", folder / "groundtruth.mat"
    features = _load_mat(features_path, ("features", "timestamp"))
    truth = _load_mat(truth_path, ("GTgroups", "GTtimestamp"))
    frames_people = _cells(features["features"], features_path, "features")
    timestamps = _numbers(features["timestamp"], features_path, "timestamp")
    truth_groups = _cells(truth["GTgroups"], truth_path, "GTgroups")
    truth_timestamps = _numbers(truth["GTtimestamp"], truth_path, "GTtimestamp")
    if len(frames_people) != len(timestamps):
        raise ValueError(f"{features_path}: {len(frames_people)} feature frames but {len(timestamps)} timestamps")
    if len(truth_groups) != len(truth_timestamps):
        raise ValueError(f"{truth_path}: {len(truth_groups)} GTgroups frames but {len(truth_timestamps)} GTtimestamps")
    index = {float(t): k for k, t in enumerate(timestamps)}
    frames = []
    for groups_cell, stamp in zip(truth_groups, truth_timestamps, strict=True):
        if float(stamp) not in index:
            raise ValueError(f"{truth_path}: GTtimestamp {stamp} has no frame in {features_path.name}")
        where = f"{features_path} frame at timestamp {stamp}"
        people = _people(frames_people[index[float(stamp)]], scale, where)
        groups = [g for g in _groups(groups_cell, f"{truth_path} at timestamp {stamp}") if len(g) > 1]
        frames.append(LabelledFrame(folder.name, float(stamp), people, groups))
    return frames


def load_dataset(folder: str | Path, scale: float = 1.0) -> list[LabelledFrame]:
    """All ground-truth frames of a dataset folder: its own sequence, or those of its sub-folders, pooled."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"fformation: {folder} is not a folder")
    if (folder / "features.mat").exists():
        return load_sequence(folder, scale)
    sequences = sorted(p.parent for p in folder.glob("*/features.mat"))
    if not sequences:
        raise ValueError(f"fformation: no features.mat in {folder} or its sub-folders")
    return [frame for sequence in sequences for frame in load_sequence(sequence, scale)]


LIKELY_METRES_M = 5.0
"""People in a conversation stand well within this of their nearest neighbour (m); a median nearest-neighbour distance
above it means the positions are not in metres (the Verona sets store centimetres: pass ``scale=0.01``)."""


def median_neighbour_distance(frames: Sequence[LabelledFrame]) -> float | None:
    """Median over people of the distance to their nearest neighbour in the same frame (input units); None when no
    frame holds two people."""
    distances: list[float] = []
    for frame in frames:
        xy = np.array([(p.x, p.y) for p in frame.people], dtype=float).reshape(-1, 2)
        if len(xy) < 2:
            continue
        gaps = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
        np.fill_diagonal(gaps, np.inf)
        distances.extend(gaps.min(axis=1).tolist())
    return float(np.median(distances)) if distances else None


def frame_precision_recall(
    detected: Sequence[Iterable[int]], truth: Sequence[Iterable[int]], threshold: float
) -> tuple[float, float]:
    """Precision and recall of one frame under the tolerance ``threshold`` (T); groups of one are ignored."""
    found_sets = [frozenset(g) for g in detected if len(frozenset(g)) > 1]
    true_sets = [frozenset(g) for g in truth if len(frozenset(g)) > 1]
    true_positives = sum(any(len(g & t) / max(len(g), len(t)) >= threshold for g in found_sets) for t in true_sets)
    if not found_sets and not true_sets:
        return 1.0, 1.0
    precision = true_positives / len(found_sets) if found_sets else 1.0
    recall = true_positives / len(true_sets) if true_sets else 1.0
    if found_sets and not true_sets:
        precision = 0.0
    return precision, recall


def score(frames: Sequence[LabelledFrame], detections: Sequence[Sequence[Iterable[int]]], threshold: float) -> Score:
    """Mean precision and recall over ``frames`` of the detected groups (member ids, one list per frame), and F1."""
    if not frames:
        raise ValueError("fformation: no frames to score")
    if len(detections) != len(frames):
        raise ValueError(f"fformation: {len(detections)} detection lists for {len(frames)} frames")
    pairs = [frame_precision_recall(found, f.truth, threshold) for f, found in zip(frames, detections, strict=True)]
    precision = float(np.mean([p for p, _ in pairs]))
    recall = float(np.mean([r for _, r in pairs]))
    f1 = 2 * precision * recall / (precision + recall) if precision + recall > 0 else 0.0
    return Score(precision, recall, f1, len(frames))


def evaluate(
    datasets: Mapping[str, Sequence[LabelledFrame]],
    params: GroupParams | None = None,
    thresholds: Sequence[float] = DEFAULT_THRESHOLDS,
) -> dict[str, dict[str, dict[str, float | int]]]:
    """Scores of ``detect_groups`` (default parameters unless given) per dataset, and pooled over all their frames.

    Returns ``{dataset or "pooled": {format_threshold(T): Score.to_dict()}}``.
    """
    params = params or GroupParams()
    detected = {
        name: [[g.members for g in detect_groups(f.people, params)] for f in frames]
        for name, frames in datasets.items()
    }
    result = {
        name: {format_threshold(t): score(frames, detected[name], t).to_dict() for t in thresholds}
        for name, frames in datasets.items()
    }
    if len(datasets) > 1:
        frames = [f for name in datasets for f in datasets[name]]
        found = [d for name in datasets for d in detected[name]]
        result["pooled"] = {format_threshold(t): score(frames, found, t).to_dict() for t in thresholds}
    return result


@dataclass
class Fold:
    """One cross-validation fold: the held-out dataset, the grid point chosen on the others (field -> value), the
    chosen point's mean F1 on those others, and its F1 on the held-out set."""

    held_out: str
    chosen: dict[str, float]
    train_f1: float
    held_out_f1: float


def cross_validate(
    datasets: Mapping[str, Sequence[LabelledFrame]],
    grid: Mapping[str, Sequence[float]],
    base: GroupParams | None = None,
    threshold: float = 2 / 3,
) -> tuple[list[Fold], dict[tuple[float, ...], dict[str, float]]]:
    """Leave-one-dataset-out choice of ``GroupParams`` fields over ``grid`` (field -> candidate values, the other
    fields from ``base``): per held-out dataset, the grid point with the best mean F1 at ``threshold`` over the
    other datasets (ties: the first in grid order), scored on the held-out one.

    Returns the folds and every grid point's F1 per dataset (keyed by its values in ``grid``'s field order).
    Needs at least two datasets; raises ValueError for an unknown field or an empty grid.
    """
    if len(datasets) < 2:
        raise ValueError("fformation: cross-validation needs at least two datasets")
    base = base or GroupParams()
    numeric = {f.name for f in dataclasses.fields(GroupParams) if f.name != "method"}
    unknown = sorted(set(grid) - numeric)
    if unknown or not grid or not all(grid.values()):
        raise ValueError(f"fformation: the grid needs values for numeric fields of GroupParams, got {dict(grid)}")
    names = list(grid)
    table: dict[tuple[float, ...], dict[str, float]] = {}
    for values in itertools.product(*(grid[n] for n in names)):
        # Whole-number fields (min_samples, radius_steps) take the value as an int; GroupParams refuses a fraction.
        changes: dict[str, Any] = {
            n: int(v) if isinstance(getattr(base, n), int) and float(v).is_integer() else v
            for n, v in zip(names, values, strict=True)
        }
        params = dataclasses.replace(base, **changes)
        table[values] = {
            name: score(frames, [[g.members for g in detect_groups(f.people, params)] for f in frames], threshold).f1
            for name, frames in datasets.items()
        }
    folds = []
    for held_out in datasets:
        others = [n for n in datasets if n != held_out]
        best = max(table, key=lambda v: float(np.mean([table[v][n] for n in others])))
        train = float(np.mean([table[best][n] for n in others]))
        folds.append(Fold(held_out, dict(zip(names, best, strict=True)), train, table[best][held_out]))
    return folds, table


def format_threshold(threshold: float) -> str:
    """'2/3' for 2/3, '1' for 1, else the decimal."""
    for num, den in ((2, 3), (1, 1), (1, 2), (3, 4), (1, 3)):
        if math.isclose(threshold, num / den):
            return f"{num}/{den}" if den != 1 else str(num)
    return f"{threshold:g}"


def parse_threshold(text: str) -> float:
    """'2/3', '0.75' or '1' -> a tolerance T in (0, 1]."""
    try:
        if "/" in text:
            num, den = text.split("/", 1)
            value = float(num) / float(den)
        else:
            value = float(text)
    except (ValueError, ZeroDivisionError):
        raise ValueError(f"threshold {text!r} is not a number or fraction such as 2/3") from None
    if not 0 < value <= 1:
        raise ValueError(f"threshold {text!r} must lie in (0, 1]")
    return value


def _load_mat(path: Path, keys: tuple[str, ...]) -> dict:
    if not path.exists():
        raise ValueError(f"fformation: {path} is missing")
    try:
        data = scipy.io.loadmat(str(path))
    except Exception as exc:  # scipy raises ValueError, TypeError, MatReadError... for non-MAT input
        raise ValueError(f"fformation: cannot read {path} as a MATLAB file ({exc})") from None
    missing = [k for k in keys if k not in data]
    if missing:
        present = sorted(k for k in data if not k.startswith("__"))
        raise ValueError(f"fformation: {path} lacks the variable(s) {missing} (it holds {present})")
    return data


def _cells(value: np.ndarray, path: Path, name: str) -> list:
    if not isinstance(value, np.ndarray) or value.dtype != object:
        raise ValueError(f"fformation: {path}: {name} must be a cell array, got {getattr(value, 'dtype', type(value))}")
    return list(value.ravel())


def _numbers(value: np.ndarray, path: Path, name: str) -> np.ndarray:
    try:
        numbers = np.asarray(value, dtype=float).ravel()
    except (TypeError, ValueError):
        raise ValueError(f"fformation: {path}: {name} must be numeric") from None
    if not np.all(np.isfinite(numbers)):
        raise ValueError(f"fformation: {path}: {name} holds non-finite values")
    return numbers


def _people(cell: np.ndarray, scale: float, where: str) -> list[Person]:
    try:
        rows = np.asarray(cell, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"fformation: {where}: features must be a numeric N x 4 array") from None
    if rows.size == 0:
        return []
    if rows.ndim != 2 or rows.shape[1] < 4:
        raise ValueError(f"fformation: {where}: features must be N x 4 [id, x, y, theta], got shape {rows.shape}")
    if not np.all(np.isfinite(rows[:, :3])):
        raise ValueError(f"fformation: {where}: non-finite id or position")
    # An annotated facing is taken at full quality (1), a missing one is unknown (None, quality 0).
    return [
        Person(
            int(r[0]),
            float(r[1]) * scale,
            float(r[2]) * scale,
            *((float(r[3]), 1.0) if math.isfinite(r[3]) else (None, 0.0)),
        )
        for r in rows
    ]


def _groups(cell: object, where: str) -> list[frozenset[int]]:
    """Member-id sets from a GTgroups cell: a cell array of id arrays (possibly nested), an id array, or empty."""
    if isinstance(cell, np.ndarray) and cell.dtype == object:
        return [g for item in cell.ravel() for g in _groups(item, where)]
    try:
        ids = np.asarray(cell, dtype=float).ravel()
    except (TypeError, ValueError):
        raise ValueError(f"fformation: {where}: a group must list numeric ids") from None
    if ids.size == 0:
        return []
    if not np.all(np.isfinite(ids)):
        raise ValueError(f"fformation: {where}: non-finite group member id")
    return [frozenset(int(i) for i in ids)]
