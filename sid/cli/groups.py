"""``sid groups FILE|-``: detect conversational groups in JSON-lines frames of people.

Input, one frame per line (world frame, metres, radians; theta may be null or absent = unknown facing; the optional
orientation_quality in [0, 1] weighs the facing, default 1 when theta is given):
    {"frame": 0, "people": [{"id": 1, "x": 1.0, "y": 0.2, "theta": 3.1}, ...]}
Output, one line per good input line, flushed as it is written:
    {"frame": 0, "groups": [{"members": [1, 2], "interest_point": [x, y], "area": a, "spread": d,
                             "zone": [[x, y], ...]}]}
A malformed line (including one that is not UTF-8 text) is reported on stderr with its line number and skipped,
or ends the run with --strict (exit 1); everything written before it stays written.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import re
import sys
from collections.abc import Iterable, Iterator
from typing import IO, Any, TextIO

from sid.checks import check_limit
from sid.documents import is_number
from sid.perception.groups import GROUP_METHODS, Group, GroupParams, detect_groups
from sid.perception.people import Person


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "groups",
        help="detect conversational groups in JSON-lines frames of people",
        description=__doc__.split("\n\n", 1)[1].split("\n\n")[0] if __doc__ else None,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("file", metavar="FILE", help="JSON-lines input, or - for stdin")
    parser.add_argument("--strict", action="store_true", help="stop at the first malformed line (exit 1)")
    add_group_params(parser)
    parser.set_defaults(func=run)


def add_group_params(parser: argparse.ArgumentParser) -> None:
    """One option per GroupParams field (--method, --group-price, --eps, ...), defaulting to the record's defaults."""
    group = parser.add_argument_group("group detector parameters (metres, square metres, radians)")
    for field in dataclasses.fields(GroupParams):
        if field.name == "method":
            group.add_argument(
                "--method",
                "--group-method",
                dest="group_method",
                choices=GROUP_METHODS,
                default=field.default,
                help=f"{_field_help(field.name)} (default {field.default}; docs/groups.md)",
            )
            continue
        kind = int if isinstance(field.default, int) else float
        group.add_argument(
            "--" + field.name.replace("_", "-"),
            dest=f"group_{field.name}",
            type=kind,
            default=field.default,
            metavar="N" if kind is int else "X",
            help=f"{_field_help(field.name)} (default {field.default})",
        )


def group_params_from(args: argparse.Namespace) -> GroupParams:
    """The GroupParams given on the command line (ValueError for invalid values)."""
    return GroupParams(**{f.name: getattr(args, f"group_{f.name}") for f in dataclasses.fields(GroupParams)})


def _field_help(name: str) -> str:
    """The first sentence of the field's entry in the GroupParams docstring."""
    doc = GroupParams.__doc__ or ""
    match = re.search(rf"^\s*{name}: (.+?\.)(?=\s+[A-Z0-9(`]|\s*$)", doc, flags=re.MULTILINE | re.DOTALL)
    return " ".join(match.group(1).split()) if match else name.replace("_", " ")


def run(args: argparse.Namespace) -> int:
    try:
        params = group_params_from(args)
    except ValueError as exc:
        print(f"sid groups: {exc}", file=sys.stderr)
        return 2
    try:
        # Bytes, decoded line by line: a line that is not UTF-8 is reported and skipped like any malformed line.
        if args.file == "-":
            stream: IO[Any] = getattr(sys.stdin, "buffer", sys.stdin)
        else:
            stream = open(args.file, "rb")  # noqa: SIM115
    except OSError as exc:
        print(f"sid groups: cannot read {args.file}: {exc.strerror}", file=sys.stderr)
        return 2
    with stream:
        try:
            return process(stream, sys.stdout, sys.stderr, params, strict=args.strict)
        except BrokenPipeError:  # the reader went away (e.g. `| head`): stop quietly, as Unix tools do
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            return 0
        except OSError as exc:  # e.g. FILE is a directory, or the disk fails mid-read
            print(f"sid groups: cannot read {args.file}: {exc.strerror or exc}", file=sys.stderr)
            return 2


def process(lines: Iterable[str | bytes], out: TextIO, err: TextIO, params: GroupParams, strict: bool = False) -> int:
    """Detect groups frame by frame; returns the exit code (1 when --strict stopped at a bad line).

    ``lines`` are text, or bytes decoded here line by line as UTF-8 (a byte-order mark before the first is dropped).
    """
    skipped = 0
    for number, frame, problem in _frames(lines):
        if problem is None:
            try:
                groups = detect_groups(frame["people"], params)
            except ValueError as exc:
                problem = str(exc)
        if problem is not None:
            print(f"sid groups: line {number}: {problem}", file=err, flush=True)
            if strict:
                return 1
            skipped += 1
            continue
        out.write(json.dumps({"frame": frame["frame"], "groups": [group_to_json(g) for g in groups]}) + "\n")
        out.flush()
    if skipped:
        print(f"sid groups: skipped {skipped} malformed line(s)", file=err, flush=True)
    return 0


def group_to_json(group: Group) -> dict[str, Any]:
    return {
        "members": list(group.members),
        "interest_point": list(group.interest_point),
        "area": group.area,
        "spread": group.spread,
        "zone": group.zone.tolist(),
    }


def _frames(lines: Iterable[str | bytes]) -> Iterator[tuple[int, dict[str, Any], str | None]]:
    """(line number, {"frame", "people": [Person]}, problem or None) for each non-blank line."""
    for number, raw in enumerate(lines, start=1):
        if isinstance(raw, bytes):
            try:
                line = raw.decode("utf-8")
            except UnicodeDecodeError as exc:
                if number == 1 and raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
                    yield number, {}, "not UTF-8 text (it starts with a UTF-16 byte-order mark; save it as UTF-8)"
                else:
                    yield (
                        number,
                        {},
                        f"not UTF-8 text (byte 0x{raw[exc.start]:02x} at byte {exc.start + 1} of the line)",
                    )
                continue
        else:
            line = raw
        if number == 1:
            line = line.removeprefix("\ufeff")  # a byte-order mark (some Windows editors write one)
        if not line.strip():
            continue
        try:
            data = json.loads(line, parse_constant=_reject_constant)
        except (json.JSONDecodeError, ValueError) as exc:
            yield number, {}, f"not valid JSON ({exc})"
            continue
        except RecursionError:
            yield number, {}, "not valid JSON (nested too deeply)"
            continue
        try:
            yield number, _parse_frame(data), None
        except ValueError as exc:
            yield number, {}, str(exc)


def _reject_constant(name: str) -> float:
    raise ValueError(f"{name} is not a number")


def _parse_frame(data: Any) -> dict[str, Any]:
    if not isinstance(data, dict):
        raise ValueError("expected a JSON object with 'frame' and 'people'")
    if "people" not in data:
        raise ValueError("missing 'people'")
    if not isinstance(data["people"], list):
        raise ValueError("'people' must be a list")
    check_limit("people", len(data["people"]), "people", "people")  # before any work on them (sid.checks.Limits)
    frame = data.get("frame")  # a label, echoed back: it must stay valid JSON (1e400 would come back as Infinity)
    if not (frame is None or isinstance(frame, str) or is_number(frame)):
        raise ValueError(f"'frame' must be a finite number or a string, got {frame!r}")
    return {"frame": frame, "people": [_parse_person(p, k) for k, p in enumerate(data["people"])]}


def _parse_person(data: Any, index: int) -> Person:
    where = f"people[{index}]"
    if not isinstance(data, dict):
        raise ValueError(f"{where} must be an object with id, x, y, theta")
    for key in ("id", "x", "y"):
        if key not in data:
            raise ValueError(f"{where} is missing {key!r}")
    person_id = data["id"]
    if isinstance(person_id, bool) or not isinstance(person_id, int):
        raise ValueError(f"{where}: id must be an integer, got {person_id!r}")
    values = {}
    for key in ("x", "y", "theta", "orientation_quality"):
        value = data.get(key)
        if key in ("theta", "orientation_quality") and value is None:
            continue
        if not is_number(value):
            raise ValueError(f"{where} (id {person_id}): {key} must be a finite number, got {value!r}")
        values[key] = float(value)
    theta = values.get("theta")
    # A given facing is taken at full quality unless the line says otherwise (as in scenario files).
    quality = values.get("orientation_quality", 0.0 if theta is None else 1.0)
    if not 0.0 <= quality <= 1.0:
        raise ValueError(f"{where} (id {person_id}): orientation_quality must lie in [0, 1], got {quality!r}")
    return Person(person_id, values["x"], values["y"], theta, quality)
