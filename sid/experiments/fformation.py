"""F-formation group benchmarks: load the Verona datasets' ``.mat`` files and score a group detector on them.

Format (``features.mat`` / ``groundtruth.mat``, MATLAB v5 to v7, one folder per sequence): ``features{t}`` is an N x 4
array ``[id, x, y, theta]`` per frame with ``timestamp(t)`` (further columns are not read, with a warning; frames
stored 4 x N, one column per person, are read transposed, with a warning: ``_upright`` tells them);
``GTgroups{t}`` lists the member ids of each group at ``GTtimestamp(t)``; the variables may be one struct's fields. x, y
are ground-plane coordinates (centimetres in the public sets: use ``scale=0.01``), theta is the facing yaw in radians in
the same frame (``degrees=True`` for files in degrees). A dataset is a folder holding ``features.mat`` (one sequence) or
sub-folders that do (sequences pooled frame by frame; those without ``groundtruth.mat`` beside others that have one left
out, with a warning). Ids are whole numbers, unique within a frame; timestamps are unique within a file; a ground-truth
group is an id vector, a cell of them (or of single ids), or a matrix with one group per row (shorter ones padded
with NaN, or 0 where nobody has id 0). A ground-truth timestamp stored in single precision, or rounded by less than a
quarter of the smallest gap between frames, finds its frame.

Scoring (the protocol of this literature; its source: docs/parameters.md): only frames with ground truth are scored,
groups of one are dropped on both sides; a truth group is found when some detected group G has
|G & GT| / max(|G|, |GT|) >= T; per frame TP = found truth groups, FP = detections - TP, FN = truth - TP,
precision = TP / (TP + FP), recall = TP / (TP + FN) (nothing detected and no truth: P = R = 1; truth but nothing
detected: P = 1, R = 0; detections but no truth: P = 0, R = 1); a dataset scores the mean precision and mean recall
over its frames, and F1 = 2PR / (P + R).

``cross_validate`` chooses detector parameters leaving one dataset out at a time (docs/groups.md).
"""

from __future__ import annotations

import collections
import dataclasses
import itertools
import math
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import scipy.io

from sid.checks import YAW_LIMIT_RAD, check_limit, check_number
from sid.documents import InputWarning, plural, special_file
from sid.errors import InputError, SidError
from sid.experiments.progress import Progress
from sid.experiments.workers import map_in_workers
from sid.perception.gcff import GCFFParams
from sid.perception.groups import GroupParams, detect_groups
from sid.perception.people import Person

__all__ = [
    "DEFAULT_GRID",
    "DEFAULT_THRESHOLDS",
    "DEGREES_SHARE",
    "FACING_AGREEMENT_MIN",
    "GROUP_ERRORS",
    "Fold",
    "LabelledFrame",
    "PLAUSIBLE_MEMBER_M",
    "PLAUSIBLE_NEIGHBOUR_M",
    "PLAUSIBLE_STRIDE_M",
    "Score",
    "UNIT_SCALES",
    "YawUnitError",
    "cross_validate",
    "detect_all",
    "evaluate",
    "facing_agreement",
    "fitting_unit",
    "format_threshold",
    "frame_matches",
    "frame_precision_recall",
    "gcff_settings",
    "group_errors",
    "group_outcome",
    "is_false_group",
    "load_dataset",
    "load_dataset_any_yaw",
    "load_dataset_in_metres",
    "load_sequence",
    "load_settings_gc",
    "median_member_distance",
    "repeated_members",
    "shifted_ids",
    "median_neighbour_distance",
    "missing_members",
    "most_shared",
    "parse_threshold",
    "score",
    "score_all",
    "sequence_folders",
    "unit_warning",
    "with_facing_noise",
    "without_facings",
]

DEFAULT_THRESHOLDS: tuple[float, ...] = (2 / 3, 1.0)
DEFAULT_GRID: dict[str, tuple[float, ...]] = {
    "alone_price": (0.5, 0.65, 0.8),
    "group_price": (0.5, 0.65, 0.8, 1.0),
    "facing_slack": (0.3, 0.4, 0.5),
    "angular_weight": (0.35, 0.5, 0.75),
    "radius_max": (0.8, 1.0),
    "body_radius": (0.1, 0.2),
    "coarse_pair_reach": (0.0, 1.0, 1.5, 2.0),
}
"""The o-space parameters ``sid eval fformation --cross-validate`` chooses among, the grid that chose the
defaults (docs/groups.md)."""


class YawUnitError(SidError, ValueError):
    """A yaw beyond ``YAW_LIMIT_RAD`` read as radians: the file is in degrees, most likely. ``where``: the file and
    frame; ``reach``: the largest yaw magnitude there."""

    def __init__(self, where: str, reach: float) -> None:
        super().__init__(
            f"fformation: {where}: theta reaches {reach:g}, beyond two turns: not radians; for a file in degrees "
            "load it with degrees=True (sid eval fformation --degrees, or without --radians)"
        )
        self.where, self.reach = where, reach


@dataclass
class LabelledFrame:
    """One scored frame: the people (world frame, metres after scaling) and the true groups (member ids);
    ``unplaced``: people of the file's frame left out for a non-finite position (a lost track)."""

    sequence: str
    timestamp: float
    people: list[Person]
    truth: list[frozenset[int]]
    unplaced: int = 0


@dataclass
class Score:
    """Mean precision and recall over frames, their F1, and the number of frames scored."""

    precision: float
    recall: float
    f1: float
    frames: int

    def to_dict(self) -> dict[str, float | int]:
        return {"precision": self.precision, "recall": self.recall, "f1": self.f1, "frames": self.frames}


def load_sequence(folder: str | Path, scale: float = 1.0, degrees: bool = False) -> list[LabelledFrame]:
    """The ground-truth frames of one sequence folder (``features.mat`` + ``groundtruth.mat``).

    Positions are multiplied by ``scale`` (0.01 turns the datasets' centimetres into metres); yaws are radians, or
    degrees with ``degrees=True``. A NaN yaw becomes an unknown facing (theta None); a person with a non-finite
    position is left out and counted in the frame's ``unplaced``; ground-truth frames whose timestamp has no
    features frame are not scored, with an ``InputWarning`` (none matching: ValueError). Raises ValueError naming the
    file (and the frame) for anything malformed: among others a yaw beyond two turns (4 pi) taken as radians
    (degrees, most likely), a repeated timestamp, an id that is not a whole number or repeats within a frame.
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
        raise InputError(
            f"fformation: {features_path}: {len(frames_people)} feature frames but {len(timestamps)} timestamps"
        )
    if len(truth_groups) != len(truth_timestamps):
        raise InputError(
            f"fformation: {truth_path}: {len(truth_groups)} GTgroups frames but {len(truth_timestamps)} GTtimestamps"
        )
    frames_people = _upright(frames_people, features_path)
    _check_unique(timestamps, features_path, "timestamp")
    _check_unique(truth_timestamps, truth_path, "GTtimestamp")
    index = _frame_index(timestamps)
    near = _nearest_frames(timestamps, truth_timestamps, index)
    frames, unmatched, widest = [], [], 4  # widest: the most columns of a scored frame's features
    for groups_cell, stamp in zip(truth_groups, truth_timestamps, strict=True):
        with np.errstate(over="ignore"):  # a stamp beyond single precision's range rounds to inf: no frame
            k = index.get(float(stamp), index.get(float(np.float32(stamp)), near.get(float(stamp))))
        if k is None:
            unmatched.append(stamp)
            continue
        where = f"{features_path} frame at timestamp {timestamps[k]:g}"
        people, unplaced = _people(frames_people[k], scale, degrees, where)
        shape = np.shape(frames_people[k])
        widest = max(widest, shape[1] if len(shape) == 2 and shape[0] else 4)
        where_truth = f"{truth_path} at timestamp {stamp:g}"
        groups = [g for g in _groups(groups_cell, where_truth, {p.id for p in people}) if len(g) > 1]
        frames.append(LabelledFrame(folder.name, float(timestamps[k]), people, groups, unplaced))
    if unmatched and not frames:  # nothing matches: other clocks or units, not a slip
        raise InputError(
            f"fformation: {truth_path}: GTtimestamp {unmatched[0]} has no frame in {features_path.name}"
            + (f" (nor do the other {len(unmatched) - 1})" if len(unmatched) > 1 else "")
        )
    if widest > 4:
        warnings.warn(
            InputWarning(
                f"fformation: {features_path}: features have {widest} columns: [id, x, y, theta] are read from the "
                f"first four, the other {widest - 4} not (a second facing, e.g. the body's beside the head's, is not "
                "used)"
            ),
            stacklevel=2,
        )
    if unmatched:
        warnings.warn(
            InputWarning(
                f"fformation: {truth_path}: {plural(len(unmatched), 'ground-truth frame')} of {len(truth_timestamps)} "
                f"without a frame in {features_path.name} (first GTtimestamp {unmatched[0]:g}): not scored"
            ),
            stacklevel=2,
        )
    return frames


def _upright(frames_people: list, path: Path) -> list:
    """The features cells, each transposed (with an ``InputWarning``) when the file stores them 4 x N, one column per
    person: every frame with four rows, and either column counts that differ (people come and go; fields do not),
    fewer than four columns (no room for [id, x, y, theta]), or ids that recur from frame to frame only when read
    along the first row (the same people in every frame; read down the first column, a person's x, y and theta)."""
    cells = [np.asarray(cell) for cell in frames_people if np.size(cell)]
    shapes = {cell.shape if cell.ndim == 2 else None for cell in cells}
    if not shapes or any(shape is None or shape[0] != 4 for shape in shapes):
        return frames_people
    columns = {shape[1] for shape in shapes if shape is not None}
    if columns == {4} or (len(columns) == 1 and min(columns) > 4 and not _ids_along_rows(cells)):
        return frames_people
    warnings.warn(
        InputWarning(
            f"fformation: {path}: every frame's features have 4 rows, read as 4 x N, one column per person (transposed)"
        ),
        stacklevel=3,
    )
    return [np.asarray(cell).T if np.size(cell) else cell for cell in frames_people]


def _ids_along_rows(cells: list[np.ndarray]) -> bool:
    """Whether the first row of the (4, C) ``cells`` reads as ids and their first column does not: whole numbers
    that take fewer distinct values over the frames (the same people seen again) than the first column's."""
    along, down = np.concatenate([c[0] for c in cells]), np.concatenate([c[:, 0] for c in cells])
    with np.errstate(invalid="ignore"):
        whole = np.isfinite(along).all() and np.array_equal(along, np.round(along))
    return bool(whole and len(cells) > 1 and len(np.unique(along)) < len(np.unique(down)))


_NEAR_SHARE = 0.25
"""A ground-truth timestamp within this share of the smallest gap between two frames' timestamps of one frame is that
frame's, when every unmatched one is (``_nearest_frames``): any other frame is then at least three times as far."""


def _nearest_frames(timestamps: np.ndarray, truth: np.ndarray, index: dict[float, int]) -> dict[float, int]:
    """Ground-truth timestamp -> frame for the timestamps that match no frame exactly but lie within ``_NEAR_SHARE``
    of the smallest gap between frames of one: the same clock written with fewer digits (k / 15 s against
    round(k / 15, 3)). All or none: when one of them is not that near a frame, the clocks differ, and none is
    taken (a near match there would be chance)."""
    with np.errstate(over="ignore"):
        loose = [float(t) for t in truth if float(t) not in index and float(np.float32(t)) not in index]
    order = np.argsort(timestamps)
    ordered = timestamps[order].astype(float)
    if not loose or len(ordered) < 2 or not np.isfinite(ordered).all():
        return {}
    reach = _NEAR_SHARE * float(np.diff(ordered).min())
    at = np.clip(np.searchsorted(ordered, loose), 1, len(ordered) - 1)
    nearer = np.where(np.abs(ordered[at - 1] - loose) <= np.abs(ordered[at] - loose), at - 1, at)
    if not (np.abs(ordered[nearer] - loose) <= reach).all():
        return {}
    return {t: int(order[k]) for t, k in zip(loose, nearer.tolist(), strict=True)}


def _check_unique(stamps: np.ndarray, path: Path, name: str) -> None:
    values, counts = np.unique(stamps, return_counts=True)
    if (counts > 1).any():
        repeated = ", ".join(f"{v:g}" for v in values[counts > 1][:5])
        raise InputError(f"fformation: {path}: {name} repeats {repeated}: each frame needs its own timestamp")


def _frame_index(timestamps: np.ndarray) -> dict[float, int]:
    """Frame position by timestamp, and by the timestamp rounded to single precision where that is still unique
    (a ground-truth file saved in single precision then finds its frames)."""
    index = {float(t): k for k, t in enumerate(timestamps)}
    with np.errstate(over="ignore"):  # beyond single precision's range: inf, never unique when repeated
        single = timestamps.astype(np.float32).astype(float)
    values, counts = np.unique(single, return_counts=True)
    unique = set(values[counts == 1].tolist())
    return {float(s): k for k, s in enumerate(single) if s in unique and s not in index} | index


def with_facing_noise(frames: Sequence[LabelledFrame], sigma: float, seed: int = 0) -> list[LabelledFrame]:
    """``frames`` with Gaussian noise of standard deviation ``sigma`` (rad) added to every known facing, drawn from
    one generator seeded with ``seed``, frame by frame and person by person in order (the same noise on every run)."""
    check_number("fformation", "facing noise", sigma, low=0, unit="radians")
    rng = np.random.default_rng(seed)
    noisy = []
    for frame in frames:
        draws = rng.normal(0.0, sigma, len(frame.people)).tolist()
        people = [
            dataclasses.replace(p, theta=None if p.theta is None else p.theta + d)
            for p, d in zip(frame.people, draws, strict=True)
        ]
        noisy.append(dataclasses.replace(frame, people=people))
    return noisy


def without_facings(frames: Sequence[LabelledFrame], share: float, seed: int = 0) -> list[LabelledFrame]:
    """``frames`` with each facing made unknown (theta None) with probability ``share``, as a person half hidden
    behind another gets no facing from the pipeline; one generator seeded with ``seed`` draws for everyone, frame by
    frame and person by person in order (the same facings on every run)."""
    check_number("fformation", "share of facings missing", share, low=0, high=1)
    rng = np.random.default_rng(seed)
    kept = []
    for frame in frames:
        gone = (rng.random(len(frame.people)) < share).tolist()
        people = [dataclasses.replace(p, theta=None) if g else p for p, g in zip(frame.people, gone, strict=True)]
        kept.append(dataclasses.replace(frame, people=people))
    return kept


def sequence_folders(folder: str | Path) -> list[Path]:
    """The sequence folders of a dataset folder: itself when it holds ``features.mat`` (an ``InputWarning`` when
    sub-folders do too), else its sub-folders that do, sorted (hidden ones, ``_hidden``, left out). Raises ValueError
    when there is none, and for a folder of datasets (``features.mat`` two levels down)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"fformation: {folder} is not a folder")
    sequences = sorted(p.parent for p in folder.glob("*/features.mat") if not _hidden(p.parent.name))
    if (folder / "features.mat").exists():
        if sequences:
            warnings.warn(
                InputWarning(
                    f"fformation: {folder} holds features.mat and sequence folders that do too: its own file is "
                    f"scored, {', '.join(s.name for s in sequences)} not (give their folders to score them)"
                ),
                stacklevel=2,
            )
        return [folder]
    deeper = sorted(
        {p.parent.parent.name for p in folder.glob("*/*/features.mat") if not _hidden(p.parent.parent.name)}
    )
    if deeper:  # a folder of datasets: pooling its one-sequence datasets, and leaving the others out, is no score
        datasets = sorted({s.name for s in sequences} | set(deeper))
        raise InputError(
            f"fformation: {folder} holds datasets, not one ({', '.join(datasets)}): give each dataset's folder"
        )
    if not sequences:
        raise InputError(f"fformation: no features.mat in {folder} or its sub-folders")
    return sequences


def _hidden(name: str) -> bool:
    """Whether a folder's ``name`` hides it from a dataset: a dot folder (a backup, a tool's copy) or an archiver's
    ``__MACOSX``."""
    return name.startswith(".") or name == "__MACOSX"


PLAUSIBLE_STRIDE_M = (0.05, 2.0)
"""The range (m) of GCFF strides that fit people (the published settings' range: docs/groups.md, "Other datasets"):
a scaled stride outside it was written in other units than the positions (``gcff_settings`` warns)."""


def gcff_settings(folder: str | Path, scale: float = 0.01) -> dict[str, GroupParams]:
    """Per sequence of a dataset folder (by its folder's name, as ``LabelledFrame.sequence`` holds it), the
    ``gcff`` method with that sequence's own ``settings_gc.mat``: GCFF tuned per sequence, the literature's
    reference. The settings are in the positions' units: ``scale`` turns them into metres, as it does the
    positions (``load_settings_gc``); an ``InputWarning`` names a stride that, scaled, is outside
    ``PLAUSIBLE_STRIDE_M``."""
    out = {}
    for sequence in _labelled(sequence_folders(folder))[0]:
        settings = load_settings_gc(sequence, scale=scale)
        low, high = PLAUSIBLE_STRIDE_M
        if not low <= settings.stride <= high:
            warnings.warn(
                InputWarning(
                    f"fformation: {sequence / 'settings_gc.mat'}: stride scaled by {scale:g} is {settings.stride:g} m, "
                    f"implausible for people (expected {low:g}-{high:g} m): are the settings in the positions' units?"
                ),
                stacklevel=2,
            )
        out[sequence.name] = GroupParams(method="gcff", gcff_stride=settings.stride, gcff_mdl=settings.mdl)
    return out


def load_dataset(folder: str | Path, scale: float = 1.0, degrees: bool = False) -> list[LabelledFrame]:
    """All ground-truth frames of a dataset folder: its own sequence, or those of its sub-folders, pooled
    (``load_sequence``'s ``scale`` and ``degrees``); sub-folders without ``groundtruth.mat`` beside others that
    have one are left out with an ``InputWarning``. Raises ValueError when no frame has ground truth."""
    folder = Path(folder)
    sequences, unlabelled = _labelled(sequence_folders(folder))
    if unlabelled:
        warnings.warn(
            InputWarning(
                f"fformation: {folder}: {plural(len(unlabelled), 'sequence')} without groundtruth.mat not scored: "
                + ", ".join(s.name for s in unlabelled)
            ),
            stacklevel=1,  # this line: said once when the dataset is loaded again in another unit
        )
    frames = [frame for sequence in sequences for frame in load_sequence(sequence, scale, degrees)]
    if not frames:
        raise InputError(f"fformation: {folder} has no frame with ground truth (GTtimestamp is empty)")
    return frames


def _labelled(sequences: list[Path]) -> tuple[list[Path], list[Path]]:
    """The sequence folders to score and those left out: all of them when none has ``groundtruth.mat`` (the
    first's missing file is then the error), else those that have one, and the others."""
    labelled = [s for s in sequences if (s / "groundtruth.mat").exists()]
    if not labelled:
        return sequences, []
    return labelled, [s for s in sequences if s not in labelled]


PLAUSIBLE_NEIGHBOUR_M = (0.1, 5.0)
"""The range (m) of the median distance from a person to their nearest neighbour in scenes of people talking: bodies
keep them more than 0.1 m apart, conversation within 5 m. A median outside it means the positions, as scaled, are
not metres (the Verona sets store centimetres: ``scale=0.01``)."""
PLAUSIBLE_MEMBER_M = (0.3, 2.0)
"""The range (m) of the median distance from a ground-truth group member to the nearest fellow member: people in a
conversation stand 0.4-1.5 m from the nearest other (0.60-0.91 m on the four Verona sets). Narrower than a decade, so
one unit at most fits it, and people standing alone do not pull it (in a set of mostly loners the median gap of
everyone fitted centimetres and millimetres alike)."""
UNIT_SCALES: dict[str, float] = {"metres": 1.0, "centimetres": 0.01, "millimetres": 0.001}
"""The units a dataset's positions are likely in, with the ``scale`` that turns them into metres."""


def fitting_unit(frames: Sequence[LabelledFrame], scale: float = 1.0) -> tuple[str, float] | None:
    """The unit of ``UNIT_SCALES`` (name, scale to metres) in which the positions of ``frames``, loaded with
    ``scale``, look like people's: the one in which the ground-truth groups' members stand as conversations do
    (``PLAUSIBLE_MEMBER_M``), else by everyone's nearest neighbour (``PLAUSIBLE_NEIGHBOUR_M``), nearest to it
    first; None when none does or no frame holds two people."""
    member = median_member_distance(frames)
    if member:
        low, high = PLAUSIBLE_MEMBER_M
        fit = [(unit, fit) for unit, fit in UNIT_SCALES.items() if low <= member / scale * fit <= high]
        if fit:
            return fit[0]
    gap = median_neighbour_distance(frames)
    if not gap:  # None, or 0: most people share their position with another, which no scale mends
        return None
    raw = gap / scale  # the median gap in the file's own units
    low, high = PLAUSIBLE_NEIGHBOUR_M
    fits = [(unit, fit) for unit, fit in UNIT_SCALES.items() if low <= raw * fit <= high]
    return min(fits, key=lambda item: abs(math.log10(raw * item[1])), default=None)


def unit_warning(frames: Sequence[LabelledFrame], scale: float) -> str | None:
    """Why the positions of ``frames``, loaded with ``scale``, are implausible as metres, with the scale that fits
    them best (``fitting_unit``); None when they look like metres (``PLAUSIBLE_NEIGHBOUR_M``) or no frame holds two
    people."""
    gap, member = median_neighbour_distance(frames), median_member_distance(frames)
    low, high = PLAUSIBLE_NEIGHBOUR_M
    if member and not PLAUSIBLE_MEMBER_M[0] <= member <= PLAUSIBLE_MEMBER_M[1]:
        low, high = PLAUSIBLE_MEMBER_M
        fit = fitting_unit(frames, scale)
        hint = (
            f"the file's units look like {fit[0]}, scale {fit[1]:g}"
            if fit and fit[1] != scale
            else "check the file's units (pixels of a top view?)"
        )
        return (
            f"scaled by {scale:g}, the median distance from a ground-truth group member to the nearest fellow member "
            f"is {member:.3g} m, implausible for a conversation (expected {low:g}-{high:g} m); {hint}"
        )
    if gap is None or low <= gap <= high:
        return None
    hint = "check the file's units"
    if (unit_fit := fitting_unit(frames, scale)) is not None and unit_fit[1] != scale:
        hint = f"the file's units look like {unit_fit[0]}, scale {unit_fit[1]:g}"
    return (
        f"scaled by {scale:g}, the median distance from a person to their nearest neighbour is {gap:.3g} m, "
        f"implausible for people (expected {low:g}-{high:g} m); {hint}"
    )


DEGREES_SHARE = 0.1
"""The share of a dataset's known yaws beyond two turns (``YAW_LIMIT_RAD``) as radians from which the file is read in
degrees (``load_dataset_any_yaw``; docs/groups.md, "Other datasets", gives the four sets' shares)."""


def load_dataset_any_yaw(
    folder: str | Path, scale: float = 1.0, degrees: bool | None = None
) -> tuple[list[LabelledFrame], bool]:
    """``load_dataset``, with ``degrees`` None (the default) reading the yaws as radians unless one of the dataset
    reaches beyond two turns (``YAW_LIMIT_RAD``), then all of them as degrees when at least ``DEGREES_SHARE`` of the
    known yaws do (facings span every direction, so most yaws of a file in degrees are tens of degrees or more); fewer
    are outliers among radians, in neither unit: InputError naming the first. Returns the frames and whether they
    were read as degrees."""
    if degrees is not None:
        return load_dataset(folder, scale, degrees), degrees
    try:
        return load_dataset(folder, scale, False), False
    except YawUnitError as exc:
        frames = load_dataset(folder, scale, True)
        yaws = np.abs([math.degrees(p.theta) for f in frames for p in f.people if p.theta is not None])
        beyond = float((yaws > YAW_LIMIT_RAD).mean())
        if beyond < DEGREES_SHARE:  # as radians, nearly all are within two turns: an outlier, not degrees
            raise InputError(
                f"fformation: {exc.where}: theta reaches {exc.reach:g}, beyond two turns, while {beyond:.1%} of the "
                "dataset's yaws do: neither radians nor degrees; fix that yaw (or force a unit: degrees=True, sid "
                "eval fformation --degrees or --radians)"
            ) from None
        return frames, True


def load_dataset_in_metres(
    folder: str | Path, degrees: bool | None = None
) -> tuple[list[LabelledFrame], str, float, bool]:
    """``load_dataset`` in the unit its positions fit (``fitting_unit``: metres when they look like metres, else
    centimetres or millimetres), its yaws read as ``load_dataset_any_yaw`` does: the frames in metres, the unit's
    name, its scale and whether the yaws were read as degrees. Positions that fit no unit are loaded as metres
    (``unit_warning`` says why)."""
    frames, degrees = load_dataset_any_yaw(folder, 1.0, degrees)
    unit, scale = fitting_unit(frames) or ("metres", 1.0)
    return (frames if scale == 1.0 else load_dataset(folder, scale, degrees)), unit, scale, degrees


FACING_AGREEMENT_MIN = 0.2
"""The least mean cosine between a ground-truth member's facing and the direction to their group's centre that looks
like this format's convention (yaw counter-clockwise from +x, in the positions' frame; ``facing_agreement``; the four
sets' values and those of other conventions: docs/groups.md, "Other datasets")."""


def facing_agreement(frames: Sequence[LabelledFrame]) -> float | None:
    """The mean, over ground-truth group members with a known facing, of the cosine between the facing and the
    direction to their group's centre (the mean position of its members present); None when there is none."""
    cosines = []
    for frame in frames:
        at = {p.id: p for p in frame.people}
        for group in frame.truth:
            members = [at[i] for i in sorted(group) if i in at]
            if len(members) < 2:
                continue
            cx, cy = np.mean([(p.x, p.y) for p in members], axis=0)
            for p in members:
                dx, dy = cx - p.x, cy - p.y
                norm = math.hypot(dx, dy)
                if p.theta is not None and norm > 0:
                    cosines.append((math.cos(p.theta) * dx + math.sin(p.theta) * dy) / norm)
    return float(np.mean(cosines)) if cosines else None


def missing_members(frames: Sequence[LabelledFrame]) -> tuple[int, int]:
    """(ground-truth group members absent from their frame's people, all members) over ``frames``: a few are
    annotation slips (the public Cocktail Party and GDet sets have some), many mean the groups use other ids or
    another encoding than the features."""
    missing = total = 0
    for frame in frames:
        ids = {p.id for p in frame.people}
        for group in frame.truth:
            total += len(group)
            missing += len(group - ids)
    return missing, total


def repeated_members(frames: Sequence[LabelledFrame]) -> tuple[int, int]:
    """(ground-truth members listed in two or more groups of their frame, frames with any): nobody stands in two
    F-formations at once, so these are an encoding the reader took otherwise (padding, another id scheme)."""
    repeated = frames_with = 0
    for frame in frames:
        counts = collections.Counter(i for group in frame.truth for i in group)
        twice = [i for i, n in counts.items() if n > 1]
        repeated += len(twice)
        frames_with += bool(twice)
    return repeated, frames_with


def shifted_ids(frames: Sequence[LabelledFrame]) -> int | None:
    """The shift (+1 or -1) that, added to every ground-truth member id, puts every member among their frame's
    people when the ids as given leave some out: ids counted from 0 in one file and from 1 in the other; else None."""
    missing, _ = missing_members(frames)
    if not missing:
        return None
    present = [({p.id for p in f.people}, f.truth) for f in frames]
    for shift in (1, -1):
        if all(i + shift in ids for ids, truth in present for group in truth for i in group):
            return shift
    return None


def median_member_distance(frames: Sequence[LabelledFrame]) -> float | None:
    """Median over the ground-truth groups' members present in their frame of the distance to the nearest fellow
    member (input units); None when no group has two members present, or more than a twentieth of the members are
    not among their frame's people (the groups then use other ids, and the people they name are not the members)."""
    missing, total = missing_members(frames)
    if missing > 0.05 * total:
        return None
    points = []
    for frame in frames:
        where = {p.id: (p.x, p.y) for p in frame.people}
        points += [[where[i] for i in sorted(group) if i in where] for group in frame.truth]
    return _median_nearest_other(points)


def median_neighbour_distance(frames: Sequence[LabelledFrame]) -> float | None:
    """Median over people of the distance to their nearest neighbour in the same frame (input units); None when no
    frame holds two people."""
    return _median_nearest_other([[(p.x, p.y) for p in frame.people] for frame in frames])


def _median_nearest_other(point_sets: Sequence[Sequence[tuple[float, float]]]) -> float | None:
    """Median over the points of every set of two or more of the distance to the nearest other point of its set;
    None when no set has two points."""
    distances: list[float] = []
    for points in point_sets:
        xy = np.array(points, dtype=float).reshape(-1, 2)
        if len(xy) >= 2:
            gaps = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
            np.fill_diagonal(gaps, np.inf)
            distances.extend(gaps.min(axis=1).tolist())
    return float(np.median(distances)) if distances else None


def frame_matches(
    detected: Sequence[Iterable[int]], truth: Sequence[Iterable[int]], threshold: float
) -> tuple[int, int, int]:
    """(true groups found, groups detected, true groups) of one frame under the tolerance ``threshold`` (T, above
    1/2); groups of one are ignored.

    A true group is found when some detected group G has |G & truth| / max(|G|, |truth|) >= T. Above 1/2 a detected
    group holds most of at most one (disjoint) true group, so no detection counts twice and precision stays <= 1.

    Raises ValueError when T is not in (1/2, 1].
    """
    _check_threshold(threshold)
    found_sets = [frozenset(g) for g in detected if len(frozenset(g)) > 1]
    true_sets = [frozenset(g) for g in truth if len(frozenset(g)) > 1]
    true_positives = sum(any(len(g & t) / max(len(g), len(t)) >= threshold for g in found_sets) for t in true_sets)
    return true_positives, len(found_sets), len(true_sets)


def frame_precision_recall(
    detected: Sequence[Iterable[int]], truth: Sequence[Iterable[int]], threshold: float
) -> tuple[float, float]:
    """Precision and recall of one frame under the tolerance ``threshold`` (T in (1/2, 1]); groups of one are
    ignored."""
    true_positives, found, true = frame_matches(detected, truth, threshold)
    if not found and not true:
        return 1.0, 1.0
    precision = true_positives / found if found else 1.0
    recall = true_positives / true if true else 1.0
    if found and not true:
        precision = 0.0
    return precision, recall


def score(frames: Sequence[LabelledFrame], detections: Sequence[Sequence[Iterable[int]]], threshold: float) -> Score:
    """Mean precision and recall over ``frames`` of the detected groups (member ids, one list per frame), and F1."""
    if not frames:
        raise InputError("fformation: no frames to score")
    if len(detections) != len(frames):
        raise InputError(f"fformation: {len(detections)} detection lists for {len(frames)} frames")
    pairs = [frame_precision_recall(found, f.truth, threshold) for f, found in zip(frames, detections, strict=True)]
    precision = float(np.mean([p for p, _ in pairs]))
    recall = float(np.mean([r for _, r in pairs]))
    f1 = 2 * precision * recall / (precision + recall) if precision + recall > 0 else 0.0
    return Score(precision, recall, f1, len(frames))


def detect_all(
    datasets: Mapping[str, Sequence[LabelledFrame]],
    params: GroupParams | None = None,
    per_sequence: Mapping[str, Mapping[str, GroupParams]] | None = None,
) -> dict[str, list[list[tuple[int, ...]]]]:
    """The groups ``detect_groups`` finds (member ids) in every frame of each dataset, with ``params`` (the defaults
    unless given) or, sequence by sequence, ``per_sequence``'s (dataset -> sequence -> parameters)."""
    params = params or GroupParams()
    per_sequence = per_sequence or {}
    return {
        name: [
            [g.members for g in detect_groups(f.people, per_sequence.get(name, {}).get(f.sequence, params))]
            for f in frames
        ]
        for name, frames in datasets.items()
    }


def most_shared(groups: Sequence[frozenset[int]], true: frozenset[int]) -> int | None:
    """Index in ``groups`` of the group sharing the most members with ``true``, the one with fewest others (members
    not in ``true``) on ties, the first of equals; None when ``groups`` is empty."""
    if not groups:
        return None
    return max(range(len(groups)), key=lambda k: (len(groups[k] & true), -len(groups[k] - true)))


GROUP_ERRORS = ("exact", "one_too_many", "more_too_many", "lacking", "mixed", "missed")
"""How a true group can come out (``group_errors``), best first."""


def group_errors(frames: Sequence[LabelledFrame], detections: Sequence[Sequence[Iterable[int]]]) -> dict[str, int]:
    """How each true group of two or more people came out in ``detections`` (member ids per frame, as ``frames``):
    ``exact``; else, by the detected group sharing most of its members (ties: the one with fewest others), all of
    them and one other (``one_too_many``) or more (``more_too_many``), two or more of them and nobody else
    (``lacking``), two or more of them and others (``mixed``), or no detected group holds two of them (``missed``).
    Also ``false_groups``: detected groups of two or more that hold two members of no true group."""
    if len(detections) != len(frames):
        raise InputError(f"fformation: {len(detections)} detection lists for {len(frames)} frames")
    counts = dict.fromkeys((*GROUP_ERRORS, "false_groups"), 0)
    for frame, found in zip(frames, detections, strict=True):
        groups = [frozenset(g) for g in found if len(frozenset(g)) > 1]
        truth = [t for t in frame.truth if len(t) > 1]
        for true in truth:
            counts[group_outcome(true, groups)] += 1
        counts["false_groups"] += sum(is_false_group(g, truth) for g in groups)
    return counts


def group_outcome(true: frozenset[int], groups: Sequence[frozenset[int]]) -> str:
    """How the true group ``true`` came out among one frame's detected ``groups`` (member-id sets of two or more):
    one of ``GROUP_ERRORS``, as ``group_errors`` counts them."""
    k = most_shared(groups, true)
    best = groups[k] if k is not None else frozenset()
    shared, others = len(best & true), len(best - true)
    if shared < 2:
        return "missed"
    if shared == len(true):
        return "exact" if not others else "one_too_many" if others == 1 else "more_too_many"
    return "mixed" if others else "lacking"


def is_false_group(group: frozenset[int], truth: Sequence[frozenset[int]]) -> bool:
    """Whether the detected ``group`` holds two members of none of the frame's true groups ``truth``."""
    return all(len(group & t) < 2 for t in truth)


def evaluate(
    datasets: Mapping[str, Sequence[LabelledFrame]],
    params: GroupParams | None = None,
    thresholds: Sequence[float] = DEFAULT_THRESHOLDS,
    per_sequence: Mapping[str, Mapping[str, GroupParams]] | None = None,
) -> dict[str, dict[str, dict[str, float | int]]]:
    """Scores of ``detect_groups`` (default parameters unless given) per dataset, and pooled over all their frames;
    ``per_sequence`` (dataset -> sequence -> parameters, e.g. ``gcff_settings``) overrides them sequence by
    sequence.

    Returns ``{dataset or "pooled": {format_threshold(T): Score.to_dict()}}``.
    """
    return score_all(datasets, detect_all(datasets, params, per_sequence), thresholds)


def score_all(
    datasets: Mapping[str, Sequence[LabelledFrame]],
    detected: Mapping[str, Sequence[Sequence[Iterable[int]]]],
    thresholds: Sequence[float] = DEFAULT_THRESHOLDS,
) -> dict[str, dict[str, dict[str, float | int]]]:
    """``evaluate``'s scores of groups already found (``detect_all``'s, dataset -> member ids per frame)."""
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
    workers: int = 1,
    progress: Progress | None = None,
) -> tuple[list[Fold], dict[tuple[float, ...], dict[str, float]]]:
    """Leave-one-dataset-out choice of ``GroupParams`` fields over ``grid`` (field -> candidate values, the other
    fields from ``base``): per held-out dataset, the grid point with the best mean F1 at ``threshold`` over the
    other datasets (ties: the first in grid order), scored on the held-out one. The grid points are scored in
    ``workers`` processes (``sid.experiments.workers``; the same table as one), ``progress`` after each.

    Returns the folds and every grid point's F1 per dataset (keyed by its values in ``grid``'s field order).
    Needs at least two datasets; raises ValueError for an unknown field or an empty grid.
    """
    if len(datasets) < 2:
        raise InputError("fformation: cross-validation needs at least two datasets")
    base = base or GroupParams()
    numeric = {f.name for f in dataclasses.fields(GroupParams) if f.name != "method"}
    unknown = sorted(set(grid) - numeric)
    if unknown or not grid or not all(grid.values()):
        raise InputError(f"fformation: the grid needs values for numeric fields of GroupParams, got {dict(grid)}")
    names = list(grid)
    points = list(itertools.product(*(grid[n] for n in names)))
    params = []
    for values in points:
        # Whole-number fields (min_samples, radius_steps) take the value as an int; GroupParams refuses a fraction.
        changes: dict[str, Any] = {
            n: int(v) if isinstance(getattr(base, n), int) and float(v).is_integer() else v
            for n, v in zip(names, values, strict=True)
        }
        params.append(dataclasses.replace(base, **changes))  # a bad value fails here, before any work
    scores = map_in_workers(_grid_point_f1, (datasets, threshold), params, workers, progress, "grid points")
    table = dict(zip(points, scores, strict=True))
    folds = []
    for held_out in datasets:
        others = [n for n in datasets if n != held_out]
        best = max(table, key=lambda v: float(np.mean([table[v][n] for n in others])))
        train = float(np.mean([table[best][n] for n in others]))
        folds.append(Fold(held_out, dict(zip(names, best, strict=True)), train, table[best][held_out]))
    return folds, table


def _grid_point_f1(
    shared: tuple[Mapping[str, Sequence[LabelledFrame]], float], params: GroupParams
) -> dict[str, float]:
    """F1 at the threshold of the groups ``params`` find, per dataset (``cross_validate``'s task)."""
    datasets, threshold = shared
    return {
        name: score(frames, [[g.members for g in detect_groups(f.people, params)] for f in frames], threshold).f1
        for name, frames in datasets.items()
    }


def format_threshold(threshold: float) -> str:
    """'2/3' for 2/3, '1' for 1, else the decimal."""
    for num, den in ((2, 3), (1, 1), (3, 4)):
        if math.isclose(threshold, num / den):
            return f"{num}/{den}" if den != 1 else str(num)
    return f"{threshold:g}"


def _check_threshold(threshold: float) -> None:
    """Raise ValueError unless the tolerance ``threshold`` lies in (1/2, 1], where the protocol is defined (at 1/2
    or below one detected group could find two true groups)."""
    if not 0.5 < threshold <= 1:
        raise InputError(f"threshold {threshold:g} must lie in (1/2, 1], e.g. 2/3 or 1")


def parse_threshold(text: str) -> float:
    """'2/3', '0.75' or '1' -> a tolerance T in (1/2, 1]."""
    try:
        if "/" in text:
            num, den = text.split("/", 1)
            value = float(num) / float(den)
        else:
            value = float(text)
    except (ValueError, ZeroDivisionError):
        raise InputError(f"threshold {text!r} is not a number or fraction such as 2/3") from None
    _check_threshold(value)
    return value


def load_settings_gc(folder: str | Path, base: GCFFParams | None = None, scale: float = 0.01) -> GCFFParams:
    """The GCFF settings in ``settings_gc.mat`` of a benchmark sequence folder (or that file itself): ``stride`` in
    the units of the sequence's positions and ``mdl`` in their square, returned in metres and square metres
    (stride x ``scale``, mdl x ``scale``^2; 0.01, the default, for the public sets' centimetres); the other fields
    from ``base`` (default ``GCFFParams()``).

    Raises ValueError naming the file when it is missing, unreadable, or lacks a finite scalar stride >= 0 or
    mdl > 0.
    """
    path = Path(folder)
    if path.is_dir():
        path = path / "settings_gc.mat"
    data = _load_mat(path, ("stride", "mdl"))
    values = {}
    for name in ("stride", "mdl"):
        array = _real(data[name], f"{path}: {name} must be a number")
        if array.size != 1 or not math.isfinite(float(array.ravel()[0])):
            raise InputError(f"fformation: {path}: {name} must be one finite number, got {array.ravel()[:4]}")
        values[name] = float(array.ravel()[0])
    check_number("fformation", "scale", scale, low=0, low_open=True)
    unit = {0.01: "cm", 0.001: "mm", 1.0: "m"}.get(scale, f"x {scale:g} m")
    try:
        stride, mdl = values["stride"] * scale, values["mdl"] * scale * scale
        return dataclasses.replace(base or GCFFParams(), stride=stride, mdl=mdl)
    except ValueError as exc:
        reason = str(exc).removeprefix("gcff: ")
        raise InputError(
            f"fformation: {path}: {reason} (from {values['stride']:g} {unit}, {values['mdl']:g} {unit}^2)"
        ) from None


def _load_mat(path: Path, keys: tuple[str, ...]) -> dict[str, Any]:
    if not path.exists():
        others = sorted(p.name for p in path.parent.glob("*") if p.suffix.lower() == ".mat" and p.is_file())
        beside = f" (the folder holds {', '.join(others[:5])}{', ...' if len(others) > 5 else ''})" if others else ""
        raise InputError(f"fformation: {path} is missing{beside}")
    special = special_file(path)
    if special:
        raise InputError(f"fformation: cannot read {path}: {special}")
    try:
        data = scipy.io.loadmat(str(path))
    except NotImplementedError:  # scipy's answer to a v7.3 file, which is HDF5 inside
        raise InputError(
            f"fformation: cannot read {path}: it is a MATLAB v7.3 (HDF5) file; save it again in MATLAB with "
            "save(FILE, ..., '-v7')"
        ) from None
    except Exception as exc:  # scipy raises ValueError, TypeError, MatReadError... for non-MAT input
        raise InputError(f"fformation: cannot read {path} as a MATLAB file ({exc})") from None
    missing = [k for k in keys if k not in data]
    # The variables as the fields of one struct (MATLAB's save(FILE, 'S') of a struct S holding them).
    holders = [v for k, v in data.items() if not k.startswith("__") and set(missing) <= set(_fields(v))]
    if missing and len(holders) == 1:
        data = data | {k: holders[0][k].item() for k in missing}
        missing = []
    if missing:
        present = sorted(k for k in data if not k.startswith("__"))
        raise InputError(f"fformation: {path} lacks the variable(s) {missing} (it holds {present})")
    return data


def _fields(value: object) -> tuple[str, ...]:
    """The field names of a MATLAB struct of one element as scipy reads it; () for anything else."""
    if isinstance(value, np.ndarray) and value.dtype.names and value.size == 1:
        return value.dtype.names
    return ()


def _cells(value: np.ndarray, path: Path, name: str) -> list:
    if not isinstance(value, np.ndarray) or value.dtype != object:
        names = getattr(getattr(value, "dtype", None), "names", None)
        got = f"a struct array (fields {', '.join(names)})" if names else getattr(value, "dtype", type(value))
        raise InputError(f"fformation: {path}: {name} must be a cell array, got {got}")
    return list(value.ravel())


def _real(value: object, problem: str) -> np.ndarray:
    """``value`` as a float array; ValueError ``fformation: PROBLEM`` unless it holds real numbers (complex ones
    too, whose imaginary part numpy would drop with only a ComplexWarning)."""
    try:
        array = np.asarray(value)
        if np.iscomplexobj(array):
            raise InputError("complex")
        return np.asarray(array, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"fformation: {problem}") from None


def _numbers(value: np.ndarray, path: Path, name: str) -> np.ndarray:
    numbers = _real(value, f"{path}: {name} must be real numbers").ravel()
    if not np.all(np.isfinite(numbers)):
        raise InputError(f"fformation: {path}: {name} holds non-finite values")
    return numbers


def _people(cell: np.ndarray, scale: float, degrees: bool, where: str) -> tuple[list[Person], int]:
    """The people of a features cell, and how many rows were left out for a non-finite position."""
    rows = _real(cell, f"{where}: features must be a real N x 4 array")
    if rows.size == 0:
        return [], 0
    if rows.ndim != 2 or rows.shape[1] < 4:
        raise InputError(f"fformation: {where}: features must be N x 4 [id, x, y, theta], got shape {rows.shape}")
    check_limit(f"fformation: {where}: features", len(rows), "people", "people")  # as sid groups, before grouping
    if not np.all(np.isfinite(rows[:, 0])):
        raise InputError(f"fformation: {where}: non-finite person id")
    ids = rows[:, 0]
    if not np.array_equal(ids, np.round(ids)):
        raise InputError(
            f"fformation: {where}: ids (first column) must be whole numbers, got {ids[ids != np.round(ids)][0]:g} "
            "(a transposed array? features are N x 4 [id, x, y, theta], one row per person)"
        )
    values, counts = np.unique(ids, return_counts=True)
    if (counts > 1).any():
        raise InputError(f"fformation: {where}: person id {values[counts > 1][0]:g} appears more than once")
    placed = np.isfinite(rows[:, 1:3]).all(axis=1)  # a person without a position (a lost track) is left out
    unplaced = int(len(rows) - placed.sum())
    rows = rows[placed]
    yaw = np.radians(rows[:, 3]) if degrees else rows[:, 3]
    reach = float(np.abs(yaw[np.isfinite(yaw)]).max(initial=0.0))
    if reach > YAW_LIMIT_RAD and degrees:  # read as degrees already: no unit makes it an angle
        raise InputError(
            f"fformation: {where}: theta reaches {math.degrees(reach):g} degrees, beyond two turns (720): neither "
            "radians nor degrees"
        )
    if reach > YAW_LIMIT_RAD:
        raise YawUnitError(where, reach)
    with np.errstate(over="ignore"):
        xy = rows[:, 1:3] * scale
    overflow = ~np.isfinite(xy).all(axis=1)
    if overflow.any():
        x, y = rows[overflow][0, 1:3].tolist()
        raise InputError(f"fformation: {where}: position ({x:g}, {y:g}) scaled by {scale:g} overflows to infinity")
    # An annotated facing is taken at full quality (1), a missing one is unknown (None, quality 0).
    people = [
        Person(int(i), x, y, *((theta, 1.0) if math.isfinite(theta) else (None, 0.0)))
        for i, x, y, theta in zip(rows[:, 0].tolist(), xy[:, 0].tolist(), xy[:, 1].tolist(), yaw.tolist(), strict=True)
    ]
    return people, unplaced


def _groups(cell: object, where: str, present: set[int], depth: int = 0) -> list[frozenset[int]]:
    """Member-id sets from a frame's GTgroups cell: a cell array of id arrays (possibly nested; inside the frame's
    cell, a cell of single ids is one group), an id vector, a matrix of one group per row (shorter groups padded with
    NaN, or with 0: any 0 when nobody ``present`` has id 0, the 0s that end rows when 0 is in more than one row, as
    nobody stands in two groups), or empty. ``depth``: how many cells down from the frame's."""
    if isinstance(cell, np.ndarray) and cell.dtype == object:
        items = cell.ravel()
        if depth > 0 and len(items) and all(_is_scalar(item) for item in items):  # {{1, 2}, {3, 4, 5}}: one each
            return _groups(np.array([np.asarray(item).ravel()[0] for item in items]), where, present, depth)
        return [g for item in items for g in _groups(item, where, present, depth + 1)]
    ids = _real(cell, f"{where}: a group must list real ids")
    if ids.size == 0:
        return []
    if ids.ndim == 2 and min(ids.shape) > 1:  # MATLAB's [1 2; 3 4], two groups of two; [1 2 0; 3 4 5]: padded
        zero = ids == 0
        ending = np.flip(np.logical_and.accumulate(np.flip(zero | np.isnan(ids), axis=1), axis=1), axis=1) & zero
        rows_with_zero = int(zero.any(axis=1).sum())  # ids from 0: [0 2 9; 3 8 0] is (0, 2, 9) and (3, 8)
        padding = np.isnan(ids) | (zero & (0 not in present)) | (ending & (rows_with_zero > 1))
        return [g for row, pad in zip(ids, padding, strict=True) for g in _groups(row[~pad], where, present, depth)]
    if not np.all(np.isfinite(ids)) or not np.array_equal(ids, np.round(ids)):
        raise InputError(f"fformation: {where}: group member ids must be finite whole numbers, got {ids.ravel()[:10]}")
    return [frozenset(int(i) for i in ids.ravel().tolist())]


def _is_scalar(item: object) -> bool:
    """Whether a cell's item holds one plain number (not a cell, not a vector)."""
    array = np.asarray(item)
    return array.dtype != object and array.size == 1 and array.dtype.kind in "biuf"
