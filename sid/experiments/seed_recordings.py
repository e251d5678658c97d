"""Replay the paper authors' logged group detections through our detector and measure the agreement.

The CSVs (by default in ``../shared/data/seed-recordings``) hold one row per person per detected group per message,
written by the authors' ROS 2 node: Timestamp (whole seconds, shared by several messages), Group Index, Interaction
Area, Centroid X/Y (interest point, m), Group Radius, Person Index (order in the message), Person X/Y (m, world frame:
X forward, Y left), Person Orientation (yaw, degrees), Runtime (s). Only people in a logged group appear, and
messages without a group were not logged.

A message is a run of consecutive rows with the same Timestamp and Runtime whose (Group Index, Person Index)
keep increasing; a repeated or decreasing pair, or a new centroid for the same group, starts the next message.
Each message is one frame: its people (numbered in row order; Person Index restarts in every group) are replayed
through ``detect_groups`` and the result is compared with the logged groups.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sid.documents import special_file
from sid.errors import InputError
from sid.perception.group import Group
from sid.perception.groups import GroupParams, detect_groups
from sid.perception.people import Person

__all__ = [
    "Agreement",
    "COLUMNS",
    "LoggedFrame",
    "LoggedGroup",
    "authors_params",
    "compare",
    "frame_to_json",
    "load_recording",
    "load_recordings",
    "main",
]

COLUMNS = (
    "Timestamp",
    "Group Index",
    "Interaction Area",
    "Centroid X",
    "Centroid Y",
    "Group Radius",
    "Person Index",
    "Person X",
    "Person Y",
    "Person Orientation",
    "Runtime",
)


@dataclass
class LoggedGroup:
    """A group the authors' detector logged: member person indices, interest point (m), area (m^2)."""

    members: frozenset[int]
    interest_point: tuple[float, float]
    area: float


@dataclass
class LoggedFrame:
    """One logged message: where it came from (file, first line), its people (ids 0.. in row order), its groups."""

    source: str
    line: int
    timestamp: float
    people: list[Person] = field(default_factory=list)
    groups: list[LoggedGroup] = field(default_factory=list)


@dataclass
class Agreement:
    """How our detector's groups compare with the logged ones over a set of frames."""

    frames: int
    logged_groups: int
    same_members: int
    interest_point_errors: list[float]
    extra_groups: int

    @property
    def membership_agreement(self) -> float:
        """Fraction of logged groups that we find with exactly the same members."""
        return self.same_members / self.logged_groups if self.logged_groups else math.nan

    @property
    def interest_point_median(self) -> float:
        """Median distance (m) between our interest point and theirs, over groups found with the same members."""
        return float(np.median(self.interest_point_errors)) if self.interest_point_errors else math.nan

    def to_dict(self) -> dict[str, float | int]:
        errors = np.asarray(self.interest_point_errors)
        return {
            "frames": self.frames,
            "logged_groups": self.logged_groups,
            "same_members": self.same_members,
            "membership_agreement": self.membership_agreement,
            "interest_point_median_m": self.interest_point_median,
            "interest_point_p90_m": float(np.percentile(errors, 90)) if len(errors) else math.nan,
            "extra_groups": self.extra_groups,
        }


def load_recording(path: str | Path) -> list[LoggedFrame]:
    """The logged messages of one CSV, as frames. Raises ValueError naming the file and line when malformed."""
    path = Path(path)
    special = special_file(path)
    if special:
        raise InputError(f"cannot read {path}: {special}")
    try:
        with path.open(newline="", encoding="utf-8") as handle:
            reader = csv.DictReader(handle)
            missing = [c for c in COLUMNS if c not in (reader.fieldnames or [])]
            if missing:
                raise InputError(f"{path}: missing column(s) {missing}")
            return _frames(path.name, reader)
    except OSError as exc:
        raise InputError(f"cannot read {path}: {exc.strerror}") from None


def _frames(source: str, rows: Iterable[dict[str, str]]) -> list[LoggedFrame]:
    frames: list[LoggedFrame] = []
    previous: tuple | None = None
    for line, row in enumerate(rows, start=2):
        try:
            values = {c: float(row[c]) for c in COLUMNS}
        except (TypeError, ValueError):
            raise InputError(f"{source} line {line}: non-numeric value in {row}") from None
        if not all(math.isfinite(v) for v in values.values()):
            raise InputError(f"{source} line {line}: non-finite value in {row}")
        message = (values["Timestamp"], values["Runtime"])
        group, person = int(values["Group Index"]), int(values["Person Index"])
        centre = (values["Centroid X"], values["Centroid Y"])
        same_message = (
            previous is not None
            and previous[0] == message
            and (group > previous[1] or (group == previous[1] and person > previous[2] and centre == previous[3]))
        )
        if not same_message:
            frames.append(LoggedFrame(source, line, values["Timestamp"]))
        frame = frames[-1]
        if not frame.groups or previous is None or group != previous[1]:
            frame.groups.append(LoggedGroup(frozenset(), centre, values["Interaction Area"]))
        person_id = len(frame.people)  # Person Index restarts in each group: number the message's rows instead
        logged = frame.groups[-1]
        logged.members = logged.members | {person_id}
        theta = math.radians(values["Person Orientation"])
        # A logged facing is taken at full quality, as `sid groups` takes a line without orientation_quality.
        frame.people.append(Person(person_id, values["Person X"], values["Person Y"], theta, 1.0))
        previous = (message, group, person, centre)
    # A file may end in the middle of a message (a group with one logged member): drop such frames.
    return [f for f in frames if all(len(g.members) >= 2 for g in f.groups)]


def load_recordings(folder: str | Path) -> list[LoggedFrame]:
    """All frames of the ``*.csv`` files in ``folder``, file by file in name order."""
    paths = sorted(Path(folder).glob("*.csv"))
    if not paths:
        raise InputError(f"no .csv recordings in {folder}")
    return [frame for path in paths for frame in load_recording(path)]


def compare(frames: Sequence[LoggedFrame], params: GroupParams | None = None) -> Agreement:
    """Replay ``frames`` through ``detect_groups`` and compare with the logged groups."""
    params = params or GroupParams()
    logged = same = extra = 0
    errors: list[float] = []
    for frame in frames:
        ours: list[Group] = detect_groups(frame.people, params)
        by_members = {frozenset(g.members): g for g in ours}
        logged += len(frame.groups)
        for group in frame.groups:
            match = by_members.get(group.members)
            if match is None:
                continue
            same += 1
            errors.append(math.dist(match.interest_point, group.interest_point))
        extra += sum(1 for g in ours if frozenset(g.members) not in {lg.members for lg in frame.groups})
    return Agreement(len(frames), logged, same, errors, extra)


def authors_params() -> GroupParams:
    """The authors' settings in our detector's terms: eps 3 m, 20 m rays, area 0.5 m^2, D 3 m, one candidate per
    cluster (the paper method), no face-to-face rule. (Their DBSCAN also used the yaw in radians as a third
    coordinate.)"""
    return GroupParams(
        method="paper",
        eps=3.0,
        area_threshold=0.5,
        spread_threshold=3.0,
        ray_length=20.0,
        facing_tolerance=0.0,
        meeting_radius=math.inf,
    )


def frame_to_json(frame: LoggedFrame, index: int) -> str:
    """One ``sid groups`` input line for a logged frame (theta in radians)."""
    people = [{"id": p.id, "x": p.x, "y": p.y, "theta": p.theta} for p in frame.people]
    return json.dumps({"frame": index, "people": people})


def main(argv: list[str] | None = None) -> int:
    """``python -m sid.experiments.seed_recordings [FOLDER] [--jsonl]``: agreement report, or frames as JSON lines."""
    parser = argparse.ArgumentParser(prog="python -m sid.experiments.seed_recordings", description=main.__doc__)
    parser.add_argument(
        "folder", nargs="?", default=str(Path(__file__).resolve().parents[3] / "shared" / "data" / "seed-recordings")
    )
    parser.add_argument("--jsonl", action="store_true", help="print the frames as `sid groups` input instead")
    args = parser.parse_args(argv)
    try:
        frames = load_recordings(args.folder)
    except ValueError as exc:
        print(f"seed recordings: {exc}", file=sys.stderr)
        return 2
    if args.jsonl:
        for index, frame in enumerate(frames):
            print(frame_to_json(frame, index))
        return 0
    report = {"defaults": compare(frames).to_dict(), "authors_settings": compare(frames, authors_params()).to_dict()}
    print(json.dumps(report, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
