"""Pictures of the F-formation frames the group detector gets wrong (``sid eval fformation --pictures``).

Each picture is a top view (world frame of the dataset, metres, y up) drawn by ``costmap.render.render_costmap``: the
people with their facing arrows and ids (unknown facings without an arrow, "id?"), each true group as a dashed outline
coloured by how it came out (``group_outcome``), each detected group as a solid one (``FALSE_GROUP`` when it holds two
members of no true group). People are coloured as their true group's outline, people in none as ``PERSON``.
"""

from __future__ import annotations

import csv
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import shapely

from costmap.grid import Costmap2D, GridSpec
from costmap.render import (
    PERSON,
    TEXT,
    Extra,
    dashed_polyline,
    person_swatch,
    render_costmap,
    world_to_image,
)
from sid.experiments.fformation import (
    GROUP_ERRORS,
    LabelledFrame,
    format_threshold,
    frame_precision_recall,
    group_outcome,
    is_false_group,
)
from sid.perception.people import Person

__all__ = [
    "DETECTED",
    "FALSE_GROUP",
    "FrameErrors",
    "INDEX",
    "OUTCOME_COLOURS",
    "OUTCOME_NAMES",
    "PICTURES",
    "error_frames",
    "frame_picture",
    "write_error_pictures",
]

OUTCOME_COLOURS: dict[str, tuple[int, int, int]] = {  # BGR
    "exact": (40, 150, 20),  # green
    "one_too_many": (0, 150, 240),  # orange
    "more_too_many": (20, 70, 140),  # brown
    "lacking": (190, 60, 100),  # violet
    "mixed": (160, 0, 170),  # purple
    "missed": (30, 30, 220),  # red
}
"""The colour of a true group's dashed outline, and of its members, by how it came out (``GROUP_ERRORS``)."""
FALSE_GROUP = (140, 120, 0)  # BGR dark cyan
"""The solid outline of a detected group holding two members of no true group."""
DETECTED = TEXT
"""The solid outline of the other detected groups."""
OUTCOME_NAMES = {
    "exact": "exact",
    "one_too_many": "all + one other",
    "more_too_many": "all + more others",
    "lacking": "some, nobody else",
    "mixed": "some + others",
    "missed": "missed",
}
"""How each way a true group came out reads in the pictures' legend (as in docs/groups.md's table)."""
TRUE_MARGIN, FOUND_MARGIN = 0.45, 0.3
"""How far (m) the true groups' dashed outlines and the detected groups' solid ones lie outside their members'
centres: apart, so that a group found exactly shows both."""
VIEW_MARGIN, VIEW_LEAST, CELL = 1.0, 4.0, 0.05
"""The view: the people's extent and this margin (m) on each side, at least this wide and high (m), in cells of
this size (m)."""
PICTURES, INDEX = "frame_*.png", "index.csv"
"""The files ``write_error_pictures`` writes (and owns in its folder)."""


@dataclass
class FrameErrors:
    """One frame with errors: its dataset, its position among the dataset's frames, how each true group came out
    (member ids -> one of ``GROUP_ERRORS``), the detected groups holding two members of no true group, and the
    frame's precision and recall at each tolerance T (``format_threshold(T)`` -> (P, R))."""

    dataset: str
    position: int
    frame: LabelledFrame
    found: list[frozenset[int]]
    outcomes: dict[frozenset[int], str]
    false_groups: list[frozenset[int]]
    scores: dict[str, tuple[float, float]]

    def counts(self) -> dict[str, int]:
        """How many true groups came out each way but exact, and the false groups; only those above 0."""
        kinds = [*(o for o in self.outcomes.values() if o != "exact"), *["false_groups"] * len(self.false_groups)]
        return {k: kinds.count(k) for k in (*GROUP_ERRORS, "false_groups") if k in kinds}

    def wrong(self) -> int:
        """How many things are wrong: the true groups not found exactly and the false groups."""
        return sum(self.counts().values())


def error_frames(
    dataset: str,
    frames: Sequence[LabelledFrame],
    detections: Sequence[Sequence[Iterable[int]]],
    thresholds: Sequence[float],
) -> list[FrameErrors]:
    """The frames of ``dataset`` with a true group not found exactly or a false group, worst first: by the frame's
    F1 at T = 1 (exact groups only; every error lowers it), then by how many things are wrong, then in file order."""
    found_frames = []
    for position, (frame, found) in enumerate(zip(frames, detections, strict=True)):
        groups = [frozenset(g) for g in found if len(frozenset(g)) > 1]
        truth = [t for t in frame.truth if len(t) > 1]
        outcomes = {t: group_outcome(t, groups) for t in truth}
        false_groups = [g for g in groups if is_false_group(g, truth)]
        if false_groups or any(o != "exact" for o in outcomes.values()):
            scores = {format_threshold(t): frame_precision_recall(groups, truth, t) for t in thresholds}
            found_frames.append(FrameErrors(dataset, position, frame, groups, outcomes, false_groups, scores))

    def exact_f1(errors: FrameErrors) -> float:
        p, r = frame_precision_recall(errors.found, errors.frame.truth, 1.0)
        return 2 * p * r / (p + r) if p + r else 0.0

    return sorted(found_frames, key=lambda e: (exact_f1(e), -e.wrong(), e.position))


def _outline(people: Mapping[int, Person], members: Iterable[int], margin: float) -> np.ndarray | None:
    """The members' convex hull grown by ``margin`` (m): its ring's world points (N, 2); None when no member is
    among ``people`` (an annotation slip)."""
    xy = [(people[m].x, people[m].y) for m in members if m in people]
    if not xy:
        return None
    ring = shapely.MultiPoint(xy).convex_hull.buffer(margin, quad_segs=8).exterior
    return shapely.get_coordinates(ring)


def _outlines(
    people: Mapping[int, Person], groups: Sequence[tuple[frozenset[int], tuple[int, int, int]]], margin: float,
    dashed: bool,
) -> Callable[[np.ndarray, GridSpec, int], None]:  # fmt: skip
    """An ``Extra``'s drawing: each group's outline in its colour, dashed or solid."""

    def draw(img: np.ndarray, spec: GridSpec, scale: int) -> None:
        for members, colour in groups:
            ring = _outline(people, members, margin)
            if ring is None:
                continue
            points = world_to_image(ring, spec, scale)
            if dashed:
                dashed_polyline(img, points, True, colour, 2)
            else:
                cv2.polylines(img, [np.rint(points * 16).astype(np.int32)], True, colour, 2, cv2.LINE_AA, shift=4)

    return draw


def _nothing(img: np.ndarray, a: object, b: object) -> None:
    """An ``Extra``'s drawing (on the map) or swatch (in the legend) that draws nothing: a legend row of text alone,
    or a group of outlines whose legend row is another entry's."""


def _line_swatch(colour: tuple[int, int, int], dashed: bool) -> Callable[[np.ndarray, int, int], None]:
    def swatch(img: np.ndarray, u: int, v: int) -> None:
        if dashed:
            dashed_polyline(img, [(u - 10, v), (u + 12, v)], False, colour, 2, dash=5)
        else:
            cv2.line(img, (u - 10, v), (u + 12, v), colour, 2, cv2.LINE_AA)

    return swatch


def _view(people: Sequence[Person]) -> GridSpec:
    """The map around ``people``: their extent with ``VIEW_MARGIN`` each side, at least ``VIEW_LEAST`` across."""
    xy = np.array([(p.x, p.y) for p in people], dtype=float).reshape(-1, 2)
    low, high = (xy.min(axis=0), xy.max(axis=0)) if len(xy) else (np.zeros(2), np.zeros(2))
    size = np.maximum(high - low + 2 * VIEW_MARGIN, VIEW_LEAST)
    centre = (low + high) / 2
    origin = np.floor((centre - size / 2) / CELL) * CELL
    return GridSpec.from_size(CELL, (float(origin[0]), float(origin[1])), (float(size[0]), float(size[1])))


def frame_picture(errors: FrameErrors, title: str) -> np.ndarray:
    """A top view (BGR) of one frame with errors: people, true groups dashed and detected ones solid, coloured by
    how they came out, a legend of what is drawn, and ``title`` above."""
    people = errors.frame.people
    by_id = {p.id: p for p in people}
    colours = dict.fromkeys(by_id, PERSON)
    for members, outcome in errors.outcomes.items():
        colours.update({m: OUTCOME_COLOURS[outcome] for m in members if m in by_id})
    true_groups = [(members, OUTCOME_COLOURS[outcome]) for members, outcome in errors.outcomes.items()]
    found = [(g, FALSE_GROUP if g in errors.false_groups else DETECTED) for g in errors.found]
    extras = [
        Extra("true group, dashed:", _nothing, _outlines(by_id, true_groups, TRUE_MARGIN, True)),
        *(
            Extra(f"  {OUTCOME_NAMES[kind]}", _line_swatch(OUTCOME_COLOURS[kind], True), _nothing)
            for kind in GROUP_ERRORS
            if kind in errors.outcomes.values()
        ),
        Extra("detected group, solid", _line_swatch(DETECTED, False), _outlines(by_id, found, FOUND_MARGIN, False)),
    ]
    if errors.false_groups:
        extras.append(Extra("  false group", _line_swatch(FALSE_GROUP, False), _nothing))
    for members, outcome in errors.outcomes.items():  # annotation slips: true members the frame does not hold
        absent = sorted(members - by_id.keys())
        if absent:
            gone = "" if len(absent) == len(members) else f" {', '.join(map(str, absent))}"
            label = f"true group {', '.join(map(str, sorted(members)))}:{gone} not in the frame"
            extras.append(Extra(label, _line_swatch(OUTCOME_COLOURS[outcome], True), _nothing))
    if any(colours[p.id] == PERSON for p in people):
        extras.append(Extra("person in no true group", person_swatch(PERSON), _nothing))
    spec = _view(people)
    return render_costmap(Costmap2D.filled(spec), people, [], title=title, extras=extras, colours=colours)


def _title(errors: FrameErrors, method: str) -> str:
    scores = ", ".join(f"T {t}: P {p:.2f} R {r:.2f}" for t, (p, r) in errors.scores.items())
    where = errors.dataset if errors.frame.sequence == errors.dataset else f"{errors.dataset} / {errors.frame.sequence}"
    return f"{where}, t = {_stamp(errors.frame.timestamp)}; {method}; {scores}"


def _stamp(timestamp: float) -> str:
    """A frame's timestamp as the file holds it: every digit (Cocktail Party's are about 1e15)."""
    return f"{timestamp:.0f}" if timestamp.is_integer() else repr(timestamp)


def write_error_pictures(
    datasets: Mapping[str, Sequence[LabelledFrame]],
    detected: Mapping[str, Sequence[Sequence[Iterable[int]]]],
    folder: Path,
    most: int,
    thresholds: Sequence[float],
    method: str,
    progress: Callable[[int, int, str], None] | None = None,
) -> tuple[list[Path], dict[str, tuple[int, int]]]:
    """Into ``folder``: per dataset, a picture (``frame_DATASET_NN.png``, NN its rank) of each of its ``most`` worst
    frames with errors (``error_frames``; ``method`` names the detector in the titles, with each T's precision and
    recall), and ``index.csv``: one row per picture (dataset, rank, frame position in the dataset, sequence,
    timestamp, precision and recall at each T, the errors, the file). Returns the files written (index last) and,
    per dataset, (frames with errors, pictures written)."""
    chosen = {name: error_frames(name, frames, detected[name], thresholds) for name, frames in datasets.items()}
    drawn = [(rank, e) for found in chosen.values() for rank, e in enumerate(found[:most], start=1)]
    width = len(str(max(most, 1)))
    written, rows = [], []
    for done, (rank, errors) in enumerate(drawn):
        if progress is not None:
            progress(done, len(drawn), f"{errors.dataset} {rank}")
        path = folder / f"frame_{errors.dataset}_{rank:0{width}d}.png"
        path.write_bytes(cv2.imencode(".png", frame_picture(errors, _title(errors, method)))[1].tobytes())
        written.append(path)
        kinds = "; ".join(f"{kind} {n}" for kind, n in errors.counts().items())
        scores = [f"{v:.3f}" for p_r in errors.scores.values() for v in p_r]
        frame = errors.frame
        rows.append([errors.dataset, rank, errors.position, frame.sequence, _stamp(frame.timestamp), *scores, kinds,
                     path.name])  # fmt: skip
    if progress is not None:
        progress(len(drawn), len(drawn), "done")
    header = ["dataset", "rank", "frame", "sequence", "timestamp"]
    labels = dict.fromkeys(format_threshold(t) for t in thresholds)  # as the scores' keys: once each
    header += [f"{what} T={t}" for t in labels for what in ("precision", "recall")]
    with open(folder / INDEX, "w", newline="") as index:
        writer = csv.writer(index)
        writer.writerow([*header, "errors", "file"])
        writer.writerows(rows)
    written.append(folder / INDEX)
    return written, {name: (len(found), min(len(found), most)) for name, found in chosen.items()}
