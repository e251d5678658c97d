"""``sid track FILE|-``: track people and groups over JSON-lines detections, one time step per line.

Input, one time step per line, in one fixed ground frame (REP-103: metres, radians counter-clockwise from +x;
timestamp in seconds, each after the last good line's; theta null or absent = unknown facing; orientation_quality,
optional, in [0, 1], default 1 with a facing; id: the detector's integer id of the detection, default its index in
the list, echoed back as the track's "detection"):
    {"timestamp": 0.0, "people": [{"id": 7, "x": 2.0, "y": 0.5, "theta": 3.1}, {"x": 2.0, "y": -0.5}]}
Output, one line per good input line, flushed as it is written, the tracks as `sid detect` writes them
(docs/tracking.md; a track is listed from its third detection, or its second 0.2 s or more after the first;
velocity in m/s; group members as track ids):
    {"timestamp": 0.0, "people": [{"id": 1, "x": 2.0, "y": 0.5, "theta": 3.1, "orientation_quality": 1.0,
                                   "velocity": [vx, vy], "state": "standing"|"walking", "visible": true,
                                   "detection": 7}],
     "groups": [{"id": 1, "kind": "conversation"|"walking", "members": [1, 2], "interest_point": [x, y],
                 "area": a, "spread": d, "zone": [[x, y], ...], "velocity": [vx, vy]}],
     "timing_ms": {"track": ms, "track_groups": ms}}
A malformed line (not UTF-8 JSON, a key given twice, an unknown field, a missing or non-finite number, a theta
beyond two turns (in degrees by mistake), a timestamp not after the last good line's but within 1 s before it, two
people with one id) is reported on stderr with its line number and skipped, or ends the run with --strict (exit 2);
everything written before it stays written. A line more than the tracker's timeout (1.5 s) after the last good one
ends every track, and a note on stderr says so, once for such lines in a row (timestamps in milli- or nanoseconds make
every line one); a line more than 1 s before it (a looped recording, or the line after one stamped in the future)
starts the trackers over, with a note.
The trackers take their parameters from a parameters file (--params, its tracking block; their defaults without one),
the group detector that finds conversations among the tracks from the options below, then the file's groups block.
"""

from __future__ import annotations

import argparse
import warnings
from collections.abc import Callable, Iterable
from typing import Any, TextIO

from sid.checks import check_limit, repeated
from sid.cli.common import fail, process_json_lines, refuse_unknown_fields, run_json_lines
from sid.cli.grouping import add_json_lines_command, group_params_from, params_file_from
from sid.cli.person_json import parse_person
from sid.documents import is_number, summary
from sid.errors import InputError
from sid.perception.people import Person
from sid.tracking import TrackingSession
from sid.tracking.assignment import load_solver
from sid.tracking.tracker import TimeGapWarning

__all__ = ["LINE_FIELDS", "PERSON_FIELDS", "add_parser", "process", "run"]

LINE_FIELDS = ("timestamp", "people")
PERSON_FIELDS = ("id", "x", "y", "theta", "orientation_quality")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    add_json_lines_command(subparsers, "track", "track people and groups over JSON-lines detections", __doc__, run)


def run(args: argparse.Namespace) -> int:
    try:
        params = params_file_from(args)
        session = TrackingSession(params.tracking, group_params_from(args, params.groups))
    except ValueError as exc:
        return fail("sid track", exc)
    load_solver()  # now: lines may come live from a detector, and its first crowded one should not wait for an import
    return run_json_lines(
        "sid track", args.file, lambda lines, out, err: process(lines, out, err, session, args.strict)
    )


def process(
    lines: Iterable[str | bytes], out: TextIO, err: TextIO, session: TrackingSession, strict: bool = False
) -> int:
    """Track ``lines`` (text, or bytes decoded line by line) into ``session``, writing one JSON line per good line on
    ``out`` and each problem on ``err``; the exit code (2 when ``strict`` stopped at a bad line)."""
    return process_json_lines(
        "sid track", lines, out, err, lambda data, note: _track_line(data, session, note), strict=strict
    )


def _track_line(data: Any, session: TrackingSession, note: Callable[[str], None]) -> dict[str, Any]:
    """The output line of one parsed input line, after ``session`` tracked its people (ValueError for a malformed
    line, the session unchanged). What the trackers say of the line (a gap that ended every track, a jump back in
    time that started them over) is a ``note`` on it."""
    timestamp, people = _parse_line(data)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always", TimeGapWarning)
        update = session.track(people, float(timestamp))
    for warning in said:
        if issubclass(warning.category, TimeGapWarning):
            note(str(warning.message))
        else:
            warnings.warn(warning.message, warning.category, stacklevel=2)
    if update.reset is not None:
        note(f"{update.reset}: the trackers started over")
    return {
        "timestamp": timestamp,
        "people": [person.to_json() | {"detection": person.detection} for person in update.people],
        "groups": [group.to_json() for group in update.groups],
        "timing_ms": {name: round(ms, 3) for name, ms in update.timing_ms.items()},
    }


def _parse_line(data: Any) -> tuple[int | float, list[Person]]:
    """The timestamp (s, as given) and people of a line."""
    if not isinstance(data, dict):
        raise InputError("expected a JSON object with 'timestamp' and 'people'")
    refuse_unknown_fields(data, LINE_FIELDS)
    for key in LINE_FIELDS:
        if key not in data:
            raise InputError(f"missing {key!r}")
    timestamp = data["timestamp"]
    if not is_number(timestamp):
        raise InputError(f"'timestamp' must be a finite number of seconds, got {summary(timestamp)}")
    if not isinstance(data["people"], list):
        raise InputError("'people' must be a list")
    check_limit("people", len(data["people"]), "people", "people")  # before any work on them (sid.checks.Limits)
    people = [parse_person(person, k, PERSON_FIELDS, id_default=True) for k, person in enumerate(data["people"])]
    ids = [person.id for person in people]
    twice = repeated(ids)
    if twice is not None:
        first, second = [k for k, person_id in enumerate(ids) if person_id == twice][:2]
        defaults = [f"people[{k}]" for k in (first, second) if "id" not in data["people"][k]]
        why = f" ({defaults[0]} has no 'id': its index in the list is its id)" if defaults else ""
        raise InputError(f"people[{first}] and people[{second}] have one id, {twice}{why}")
    return timestamp, people
