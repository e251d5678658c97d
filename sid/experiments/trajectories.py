"""Real pedestrian trajectories with walking groups (ETH/BIWI, UCY), and their replay as a robot's detections.

Format (one folder per set): ``obsmat.txt``, one row per annotated person and frame,
``frame pedestrian_id pos_x pos_z pos_y v_x v_z v_y`` (metres and m/s on the ground plane; the z columns are unused);
``groups.txt``, one line per group of people who walk together, their ids separated by spaces (people not listed
walk alone; a group holds for as long as at least two of its members are in the scene). Annotations come every
``interval`` seconds (0.4 s in the public sets, whatever their video's frame rate): the most common step between a
person's consecutive frame numbers is taken as one interval (seq_eth has a few odd steps between frames; a set may
annotate different people on different frames). Unless given, the interval is read from the
annotations themselves: the median, over the people walking faster than 0.3 m/s, of how far they move in one step
over their annotated speed (0.400 s in each public set), to two significant digits. An id annotated again more than
``REUSED_AFTER_S`` after it left is taken as another person from then on (an id reused).

``replay`` feeds them as a perception stage would: detections at the annotation times or at a camera's rate by
linear interpolation (each person between their own annotations, only when one step apart), seeded Gaussian
position noise, seeded missed detections, and optionally only the people inside a robot's field of view. Positions
are in the set's own ground frame; the facing is unknown (None): the sets have none.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sid.checks import MAX_COORDINATE, check_number
from sid.documents import plural, special_file
from sid.errors import SidError
from sid.perception.people import Person
from sid.tracking.view import View

__all__ = [
    "APART_M",
    "DEFAULT_INTERVAL",
    "REUSED_AFTER_S",
    "WALKING_SPEED_MAX",
    "ReplayFrame",
    "ReplaySettings",
    "TrajectoryError",
    "TrajectorySet",
    "load_trajectory_set",
    "replay",
    "replay_length",
]


class TrajectoryError(SidError, ValueError):
    """A trajectory folder that cannot be read: the message names the file, the line and the problem."""


@dataclass(frozen=True, eq=False)
class TrajectorySet:
    """One set of annotated trajectories.

    name: the folder's name. times: (F,) annotation times (s, from 0). ids, positions, velocities: per frame, the
    people present, (K,) int, (K, 2) m and (K, 2) m/s in the set's ground frame. groups: the annotated walking
    groups (member ids; two or more each). notes: what the reader noticed, one line each. interval: seconds between
    a person's annotation steps.
    """

    name: str
    times: np.ndarray
    ids: tuple[np.ndarray, ...]
    positions: tuple[np.ndarray, ...]
    velocities: tuple[np.ndarray, ...]
    groups: tuple[frozenset[int], ...]
    notes: tuple[str, ...] = ()
    interval: float = 0.4

    @property
    def people(self) -> int:
        """Distinct people annotated."""
        return len(np.unique(np.concatenate(self.ids))) if self.ids else 0

    def truth_groups(self, present: set[int] | frozenset[int]) -> list[frozenset[int]]:
        """The annotated groups holding among ``present`` people: their members present, when two or more."""
        held = [group & present for group in self.groups]
        return [group for group in held if len(group) >= 2]


@dataclass(frozen=True)
class ReplaySettings:
    """How ``replay`` turns annotations into detections.

    rate: detections per second (None: at the annotation times; e.g. 15 for a camera, by interpolation).
    noise: standard deviation (m) of the Gaussian noise added to each coordinate. miss_rate: probability that a
    person is not detected in a frame. seed: of both. view: the robot's field of view in the set's frame (None:
    everyone is seen).
    """

    rate: float | None = None
    noise: float = 0.1
    miss_rate: float = 0.1
    seed: int = 0
    view: View | None = None

    def __post_init__(self) -> None:
        if self.rate is not None:
            check_number("replay", "rate", self.rate, low=0, low_open=True, high=1000, unit="Hz")
        check_number("replay", "noise", self.noise, low=0, high=10, unit="metres")
        check_number("replay", "miss_rate", self.miss_rate, low=0, high=1, high_open=True)


@dataclass(frozen=True)
class ReplayFrame:
    """One replayed time step: ``timestamp`` (s), the detections (``Person.id`` = the true id; ``theta`` None), and
    the truth: the ids and (K, 2) positions (m) of the people present, inside the view when one is set."""

    timestamp: float
    detections: list[Person]
    truth_ids: np.ndarray
    truth_positions: np.ndarray


DEFAULT_INTERVAL = 0.4
"""Seconds between annotation steps where the annotations cannot tell (too few people walking): the public sets'."""
WALKING_SPEED_MAX = 3.0
"""m/s: a median annotated speed of people walking above this is not in m/s (1.2-1.5 m/s in the public sets; velocities
in cm/s or km/h give 120-150 or 4.3-5.4): the time between annotation steps is not read from such velocities."""


def load_trajectory_set(folder: str | Path, interval: float | None = None) -> TrajectorySet:
    """The set in ``folder`` (``obsmat.txt``, ``groups.txt``); ``interval``: seconds between annotation steps (None:
    read from the annotated positions and velocities, the module docstring; a note says so when it is not 0.4 s)."""
    folder = Path(folder)
    if interval is not None:
        check_number("trajectories", "interval", interval, low=0, low_open=True, unit="seconds")
    obsmat, groups_file = folder / "obsmat.txt", folder / "groups.txt"
    for path in (obsmat, groups_file):
        if not path.exists():
            inside = sorted(p.parent.name for p in folder.glob(f"*/{path.name}"))  # a folder of sets
            hint = (
                f"; its sub-folders {', '.join(inside[:5])}{', ...' if len(inside) > 5 else ''} do: give them"
                if inside
                else ""
            )
            raise TrajectoryError(f"{folder}: no {path.name} (a trajectory set holds obsmat.txt and groups.txt){hint}")
    rows = _read_obsmat(obsmat)
    _check_ground_columns(obsmat, rows)
    # Sorted by frame, then pedestrian (then the rest); a row written twice is one annotation.
    rows, repeated = np.unique(rows, axis=0, return_counts=True)
    notes = [f"{obsmat.name}: {int((repeated - 1).sum())} repeated rows read once"] if (repeated > 1).any() else []
    frames = rows[:, 0].astype(np.int64)
    ids = rows[:, 1].astype(np.int64)
    step = _frame_step(frames, ids)
    twice = np.flatnonzero((frames[1:] == frames[:-1]) & (ids[1:] == ids[:-1]))  # sorted: repeats are neighbours
    if len(twice):
        raise TrajectoryError(f"{obsmat}: pedestrian {ids[twice[0]]} appears twice in frame {frames[twice[0]]}")
    starts = np.flatnonzero(np.r_[True, frames[1:] != frames[:-1]])
    bounds = np.r_[starts, len(frames)]
    position, velocity = rows[:, [2, 4]], rows[:, [5, 7]]
    if interval is None:
        interval, note = _read_interval(frames, ids, position, velocity, step)
        notes += [note] if note else []
    note = _position_note(frames, ids, position, step, interval)
    notes += [note] if note else []
    times = (frames[starts] - frames[0]) / step * interval
    groups, group_notes = _read_groups(groups_file, set(ids.tolist()))
    note = _apart_note(groups_file, groups, frames, ids, position)
    group_notes += (note,) if note else ()
    ids, aliases, note = _split_returns(frames, ids, step, interval)
    notes += [note] if note else []
    if aliases:  # a group of an id reused holds for each of its people, as it did for the one id
        groups = tuple(frozenset(j for i in group for j in (i, *aliases.get(i, ()))) for group in groups)
        order = np.lexsort((ids, frames))  # each frame's people by id again
        ids, position, velocity = ids[order], position[order], velocity[order]
    return TrajectorySet(
        folder.name,
        times,
        tuple(ids[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)),
        tuple(position[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)),
        tuple(velocity[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)),
        groups,
        (*notes, *group_notes),
        interval,
    )


REUSED_AFTER_S = 10.0
"""Seconds after which a pedestrian id annotated again is taken as another person (an id reused for someone who came
later): far longer than a track outlives its person (``TrackerParams.out_of_view_timeout``, 4 s by default)."""


def _split_returns(
    frames: np.ndarray, ids: np.ndarray, step: int, interval: float
) -> tuple[np.ndarray, dict[int, list[int]], str]:
    """``ids`` (rows sorted by frame, then id) with each return of an id after more than ``REUSED_AFTER_S`` seconds
    without it given a new id (above every id of the set), the new ids of each id so split, and a note naming them
    ("" when none)."""
    order = np.lexsort((frames, ids))  # by person, then frame
    f, i = frames[order], ids[order]
    gap = np.r_[0, np.diff(f)] / step * interval
    starts = np.r_[True, i[1:] != i[:-1]]
    returns = ~starts & (gap > REUSED_AFTER_S)
    if not returns.any():
        return ids, {}, ""
    run = np.cumsum(starts | returns)  # each person's stretches between returns, numbered in order
    later = run > np.maximum.accumulate(np.where(starts, run, 0))  # after a return of the same person
    split = np.where(later, i.max() + np.cumsum(returns), i)
    aliases: dict[int, list[int]] = {}
    for old, new in zip(i[returns].tolist(), split[returns].tolist(), strict=True):
        aliases.setdefault(old, []).append(new)
    out = np.empty_like(ids)
    out[order] = split
    longest = int(np.argmax(np.where(returns, gap, 0)))
    note = (
        f"{plural(len(aliases), 'pedestrian id')} annotated again more than {REUSED_AFTER_S:g} s after leaving "
        f"(longest: pedestrian {i[longest]}, {gap[longest]:.1f} s): each return is taken as another person (an id "
        "reused)"
    )
    return out, aliases, note


def _frame_step(frames: np.ndarray, ids: np.ndarray) -> int:
    """Frame numbers per annotation step: the most common step between a person's consecutive annotations (rows
    sorted by frame, then id); between the set's frames when nobody is annotated twice; 1 for a single frame."""
    order = np.lexsort((frames, ids))  # by person, then frame
    same = ids[order][1:] == ids[order][:-1]
    moves = np.diff(frames[order])[same]
    steps, counts = np.unique(moves if len(moves) else np.diff(np.unique(frames)), return_counts=True)
    return int(steps[np.argmax(counts)]) if len(steps) else 1


def _position_note(frames: np.ndarray, ids: np.ndarray, position: np.ndarray, step: int, interval: float) -> str:
    """A note when the people move between annotation steps faster than people walk as metres (the median of one-step
    moves over ``interval`` beyond ``WALKING_SPEED_MAX``: 1.2-1.5 m/s in the public sets): positions in pixels or
    centimetres, which the tracker's gates in metres cannot follow; else ""."""
    order = np.lexsort((frames, ids))
    f, i, p = frames[order], ids[order], position[order]
    one_step = (i[1:] == i[:-1]) & (f[1:] - f[:-1] == step)
    if one_step.sum() < 5:
        return ""
    speed = float(np.median(np.hypot(*(p[1:] - p[:-1])[one_step].T))) / interval
    if speed <= WALKING_SPEED_MAX:
        return ""
    return (
        f"the people move a median {speed:.3g} per second between annotation steps, too fast for metres (people walk "
        f"1-2 m/s): positions in another unit (pixels, centimetres)? The trackers take metres, and the scores mean "
        "nothing until the positions are converted"
    )


def _read_interval(
    frames: np.ndarray, ids: np.ndarray, position: np.ndarray, velocity: np.ndarray, step: int
) -> tuple[float, str]:
    """Seconds between annotation steps, from the rows (sorted by frame, then id): the median of |move| / |velocity|
    over one-step moves of people annotated faster than 0.3 m/s, to two significant digits; and a note when it is
    not ``DEFAULT_INTERVAL``, or when it is left at that: the velocities all 0, fewer than 5 such moves, or a median
    speed of those people beyond ``WALKING_SPEED_MAX`` (velocities in another unit than m/s)."""
    order = np.lexsort((frames, ids))  # by person, then frame
    f, i, p, v = frames[order], ids[order], position[order], velocity[order]
    one_step = (i[1:] == i[:-1]) & (f[1:] - f[:-1] == step)
    speed = np.hypot(v[:-1, 0], v[:-1, 1])
    moving = one_step & (speed > 0.3)
    taken = f"{DEFAULT_INTERVAL} s taken (--interval sets it)"
    if not np.any(velocity):
        pace = ""
        if one_step.sum() >= 5:  # what the interval taken makes of the moves: a hint when it is far off
            moves = float(np.median(np.hypot(*(p[1:] - p[:-1])[one_step].T)))
            pace = f"; at that the people move a median {moves / DEFAULT_INTERVAL:.3g} m/s (people walk 1-2 m/s)"
        return DEFAULT_INTERVAL, (
            f"the velocities (v_x, v_y) are all 0: the time between annotation steps is {taken}{pace}"
        )
    if moving.sum() < 5:
        return DEFAULT_INTERVAL, f"too few people walking to read the time between annotation steps: {taken}"
    walking = float(np.median(speed[moving]))
    if walking > WALKING_SPEED_MAX:
        return DEFAULT_INTERVAL, (
            f"the people walking have a median annotated speed of {walking:.3g}, too fast for m/s (velocities in "
            f"another unit?): the time between annotation steps is {taken}"
        )
    moved = np.hypot(*(p[1:] - p[:-1])[moving].T)
    interval = float(f"{np.median(moved / speed[moving]):.2g}")
    if abs(interval - DEFAULT_INTERVAL) <= 1e-9:
        return interval, ""
    return interval, (
        f"annotations every {interval:g} s (frame step {step}), read from the annotated positions and velocities "
        "(--interval sets it)"
    )


def replay(trajectories: TrajectorySet, settings: ReplaySettings | None = None) -> Iterator[ReplayFrame]:
    """The detections a robot's perception would give, time step by time step (see the module's docstring)."""
    settings = settings or ReplaySettings()
    rng = np.random.default_rng(settings.seed)
    for timestamp, ids, positions in _steps(trajectories, settings.rate):
        if settings.view is not None:
            inside = settings.view.contains(positions)
            ids, positions = ids[inside], positions[inside]
        measured = positions + rng.normal(0.0, settings.noise, positions.shape)
        seen = rng.random(len(ids)) >= settings.miss_rate
        detections = [
            Person(int(i), float(x), float(y))
            for i, (x, y), keep in zip(ids.tolist(), measured.tolist(), seen.tolist(), strict=True)
            if keep
        ]
        yield ReplayFrame(float(timestamp), detections, ids, positions)


def _steps(trajectories: TrajectorySet, rate: float | None) -> Iterator[tuple[float, np.ndarray, np.ndarray]]:
    """(time, ids sorted, true positions) at the annotation times, or every 1 / rate seconds from the first: each
    person at their annotation at that time, else between their last annotation and their next when that comes
    within 1.5 annotation steps (linearly; a set may annotate different people on different frames), else absent."""
    times = trajectories.times
    if len(times) == 0:
        return
    instants = times if rate is None else times[0] + np.arange(replay_length(trajectories, rate)) / rate
    # Every annotation, in time order: when, who, where, and which annotation of the same person comes next (-1:
    # none within 1.5 steps, a gap with nobody to interpolate).
    when = np.repeat(times, [len(ids) for ids in trajectories.ids])
    who, where = np.concatenate(trajectories.ids), np.concatenate(trajectories.positions)
    reach = 1.5 * trajectories.interval
    order = np.lexsort((when, who))  # by person, then time
    follows = (who[order][1:] == who[order][:-1]) & (np.diff(when[order]) <= reach)
    following = np.full(len(who), -1)
    following[order[:-1][follows]] = order[1:][follows]
    for t in instants.tolist():
        rows = np.arange(np.searchsorted(when, t - reach - 1e-9), np.searchsorted(when, t + 1e-9, side="right"))
        exact = rows[np.abs(when[rows] - t) < 1e-9]
        later = following[rows]
        between = (np.abs(when[rows] - t) >= 1e-9) & (later >= 0)
        between[between] = when[later[between]] > t + 1e-9  # else the next annotation is in the window itself
        start, end = rows[between], later[between]
        w = ((t - when[start]) / (when[end] - when[start]))[:, None]
        ids = np.concatenate([who[exact], who[start]])
        positions = np.concatenate([where[exact], (1 - w) * where[start] + w * where[end]])
        by_id = np.argsort(ids, kind="stable")
        yield t, ids[by_id], positions[by_id]


def replay_length(trajectories: TrajectorySet, rate: float | None) -> int:
    """How many frames ``replay`` yields at ``rate`` (Hz; None: one per annotation time)."""
    times = trajectories.times
    if rate is None or not len(times):
        return len(times)
    return int(math.floor((times[-1] - times[0]) * rate + 1e-9)) + 1


def _read_obsmat(path: Path) -> np.ndarray:
    rows: list[list[float]] = []
    for number, line in _lines(path):
        try:
            values = [float(v) for v in line.split()]
        except ValueError:
            raise TrajectoryError(f"{path}:{number}: not numbers: {line.strip()[:80]!r}{_separator(line)}") from None
        if len(values) != 8:
            raise TrajectoryError(f"{path}:{number}: {len(values)} columns, expected 8 (frame id x z y vx vz vy)")
        if not all(math.isfinite(v) for v in values):
            raise TrajectoryError(f"{path}:{number}: a value is not finite")
        if any(v != int(v) or abs(v) > _LARGEST_ID for v in values[:2]):
            hint = " (the first column is the frame number, not a time)" if values[0] != int(values[0]) else ""
            raise TrajectoryError(f"{path}:{number}: frame and pedestrian id must be whole numbers up to 2^53{hint}")
        if max(abs(values[2]), abs(values[4])) > MAX_COORDINATE:  # x and y, as the tracker bounds them
            raise TrajectoryError(
                f"{path}:{number}: position ({values[2]:g}, {values[4]:g}) is farther than {MAX_COORDINATE:g} m from "
                "the origin along x or y"
            )
        rows.append(values)
    if not rows:
        raise TrajectoryError(f"{path}: no annotations")
    return np.array(rows)


def _check_ground_columns(path: Path, rows: np.ndarray) -> None:
    """TrajectoryError when pos_x (column 3) or pos_y (column 5) is the same on every row while pos_z (column 4)
    varies: the columns are then in another order (x y z) than the format's (frame id x z y vx vz vy)."""
    spread = np.ptp(rows[:, 2:5], axis=0)
    for column, name in ((2, "pos_x"), (4, "pos_y")):
        if spread[column - 2] == 0 and spread[1] > 0:
            raise TrajectoryError(
                f"{path}: {name} (column {column + 1}) is {rows[0, column]:g} on every row while pos_z (column 4) "
                "varies: the columns must be frame id pos_x pos_z pos_y v_x v_z v_y (written in x y z order?)"
            )


APART_M = 2.0
"""A group whose members never come this close (m) to each other in one frame is not one: ``_apart_note``."""


def _apart_note(
    path: Path, groups: Sequence[frozenset[int]], frames: np.ndarray, ids: np.ndarray, position: np.ndarray
) -> str:
    """A note when a tenth or more of the groups never have two members within ``APART_M`` of each other in one
    frame (one such group is an annotation slip; many say that groups.txt numbers people otherwise than obsmat.txt:
    ids shifted by one, another file's ids)."""
    where: dict[int, dict[int, np.ndarray]] = {}
    for frame, person, xy in zip(frames.tolist(), ids.tolist(), position, strict=True):
        where.setdefault(person, {})[frame] = xy
    apart = [group for group in groups if not _ever_close(group, where)]
    if len(apart) < max(2, len(groups) / 10):
        return ""
    example = ", ".join(map(str, sorted(apart[0])))
    return (
        f"{path.name}: {len(apart)} of {len(groups)} groups never have two members within {APART_M:g} m of each other "
        f"(e.g. pedestrians {example}): are its ids obsmat.txt's?"
    )


def _ever_close(group: frozenset[int], where: dict[int, dict[int, np.ndarray]]) -> bool:
    """Whether two members of ``group`` stand within ``APART_M`` of each other in a frame (``where``: per person,
    frame -> position, m)."""
    for a, b in itertools.combinations(sorted(group), 2):
        shared = where[a].keys() & where[b].keys()
        if any(np.hypot(*(where[a][f] - where[b][f])) <= APART_M for f in shared):
            return True
    return False


def _read_groups(path: Path, known: set[int]) -> tuple[tuple[frozenset[int], ...], tuple[str, ...]]:
    """The groups of ``groups.txt`` and notes on it. Lines that share a person are one group (a person walks in one
    group; the public seq_eth lists some people on two lines): they are joined, and a note says which. Ids that
    obsmat.txt never annotates (an annotation slip: nobody to score) are left out, and a note says which; a note
    also says when no group is left."""
    lines: list[tuple[int, frozenset[int]]] = []
    notes: list[str] = []
    for number, line in _lines(path):
        try:
            members = frozenset(int(v) for v in line.split())
        except ValueError:
            raise TrajectoryError(f"{path}:{number}: pedestrian ids must be whole numbers{_separator(line)}") from None
        unknown = sorted(members - known)
        if unknown:
            who = f"pedestrian{'s' if len(unknown) > 1 else ''} {', '.join(map(str, unknown))}"
            notes.append(f"{path.name}:{number}: {who} not in obsmat.txt: left out")
            members -= frozenset(unknown)
        lines.append((number, members))
    joined: list[tuple[list[int], frozenset[int]]] = []
    for number, members in lines:
        overlapping = [j for j in joined if j[1] & members]
        numbers = [number] + [n for j in overlapping for n in j[0]]
        union = members.union(*(j[1] for j in overlapping))
        joined = [j for j in joined if not j[1] & members] + [(sorted(numbers), union)]
    notes += [
        f"{path.name}: lines {', '.join(map(str, numbers))} share people: taken as one group of {len(members)}"
        for numbers, members in joined
        if len(numbers) > 1
    ]
    groups = [members for _, members in sorted(joined, key=lambda j: j[0]) if len(members) >= 2]
    if not groups:
        notes.append(f"{path.name} holds no group of two or more annotated people: everyone is scored as walking alone")
    return tuple(groups), tuple(notes)


def _separator(line: str) -> str:
    """A hint for a line that is not numbers: a CSV export's commas or semicolons are not the format's separator."""
    return " (values are separated by spaces or tabs)" if "," in line or ";" in line else ""


_LARGEST_ID = 2**53  # frame numbers and ids are read as floats: whole numbers beyond this are not exact


def _lines(path: Path) -> Iterator[tuple[int, str]]:
    """(line number, line) for the non-blank lines of a UTF-8 text file (a byte-order mark first is dropped, as
    ``sid.documents.load_document`` drops it); TrajectoryError naming a line that is not."""
    special = special_file(path)
    if special:
        raise TrajectoryError(f"{path}: cannot read it: {special}")
    with path.open("rb") as handle:
        for number, raw in enumerate(handle, 1):
            try:
                line = raw.decode("utf-8-sig" if number == 1 else "utf-8")  # a byte-order mark first, as Notepad
            except UnicodeDecodeError:
                raise TrajectoryError(f"{path}:{number}: not UTF-8 text") from None
            if line.strip():
                yield number, line
