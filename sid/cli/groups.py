"""``sid groups FILE|-``: detect conversational groups in JSON-lines frames of people.

Input, one frame per line (world frame, metres, radians; theta may be null or absent = unknown facing; the optional
orientation_quality in [0, 1] weighs the facing, default 1 when theta is given):
    {"frame": 0, "people": [{"id": 1, "x": 1.0, "y": 0.2, "theta": 3.1}, ...]}
Output, one line per good input line, flushed as it is written:
    {"frame": 0, "groups": [{"members": [1, 2], "interest_point": [x, y], "area": a, "spread": d,
                             "zone": [[x, y], ...]}]}
A malformed line (one that is not UTF-8 JSON, gives a key twice, has a field not named above or a theta beyond two
turns, in degrees by mistake) is reported on stderr with its line number and skipped, or ends the run with --strict
(exit 2); everything written before it stays written.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterable
from typing import Any, TextIO

from sid.checks import check_limit
from sid.cli.common import fail, process_json_lines, refuse_unknown_fields, run_json_lines
from sid.cli.grouping import add_json_lines_command, group_params_from, params_file_from
from sid.cli.person_json import parse_person
from sid.documents import is_number, summary
from sid.errors import InputError
from sid.perception.group import group_json
from sid.perception.groups import GroupParams, detect_groups

__all__ = ["LINE_FIELDS", "PERSON_FIELDS", "add_parser", "process", "run"]

LINE_FIELDS = ("frame", "people")
PERSON_FIELDS = ("id", "x", "y", "theta", "orientation_quality")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    add_json_lines_command(
        subparsers, "groups", "detect conversational groups in JSON-lines frames of people", __doc__, run
    )


def run(args: argparse.Namespace) -> int:
    try:
        params = group_params_from(args, params_file_from(args).groups)
    except ValueError as exc:
        return fail("sid groups", exc)
    return run_json_lines(
        "sid groups", args.file, lambda lines, out, err: process(lines, out, err, params, args.strict)
    )


def process(lines: Iterable[str | bytes], out: TextIO, err: TextIO, params: GroupParams, strict: bool = False) -> int:
    """Detect groups frame by frame, writing one JSON line per good line on ``out`` and each problem on ``err``;
    returns the exit code (2 when ``strict`` stopped at a bad line).

    ``lines`` are text, or bytes decoded here line by line as UTF-8 (a byte-order mark before the first is dropped).
    """
    return process_json_lines(
        "sid groups", lines, out, err, lambda data, _note: _groups_line(data, params), strict=strict
    )


def _groups_line(data: Any, params: GroupParams) -> dict[str, Any]:
    """The output line of one parsed input line: its frame label and groups (ValueError for a malformed line)."""
    frame = _parse_frame(data)
    return {"frame": frame["frame"], "groups": [group_json(g) for g in detect_groups(frame["people"], params)]}


def _parse_frame(data: Any) -> dict[str, Any]:
    if not isinstance(data, dict):
        raise InputError("expected a JSON object with 'frame' and 'people'")
    refuse_unknown_fields(data, LINE_FIELDS)
    if "people" not in data:
        raise InputError("missing 'people'")
    if not isinstance(data["people"], list):
        raise InputError("'people' must be a list")
    check_limit("people", len(data["people"]), "people", "people")  # before any work on them (sid.checks.Limits)
    frame = data.get("frame")  # a label, echoed back: it must stay valid JSON (1e400 would come back as Infinity)
    if not (frame is None or isinstance(frame, str) or is_number(frame)):
        raise InputError(f"'frame' must be a finite number or a string, got {summary(frame)}")
    return {"frame": frame, "people": [parse_person(p, k, PERSON_FIELDS) for k, p in enumerate(data["people"])]}
