"""The group detector's options (one per ``GroupParams`` field), shared by ``sid groups``, ``sid track`` and
``sid eval``."""

from __future__ import annotations

import argparse
import dataclasses
import re
from collections.abc import Callable

from sid.cli.common import plain_text
from sid.perception.groups import GROUP_METHODS, GroupParams

__all__ = ["add_group_params", "add_json_lines_command", "group_params_from"]


def add_json_lines_command(
    subparsers: argparse._SubParsersAction,
    name: str,
    summary: str,
    doc: str | None,
    run: Callable[[argparse.Namespace], int],
) -> argparse.ArgumentParser:
    """A command on JSON lines of people (``sid groups``, ``sid track``): FILE or - for stdin, ``--strict`` and the
    group detector's parameters; its description is the second paragraph of the module docstring ``doc``."""
    parser = subparsers.add_parser(
        name,
        help=summary,
        description=plain_text(doc.split("\n\n", 1)[1].split("\n\n")[0]) if doc else None,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("file", metavar="FILE", help="JSON-lines input, or - for stdin")
    parser.add_argument("--strict", action="store_true", help="stop at the first malformed line (exit 2)")
    add_group_params(parser)
    parser.set_defaults(func=run)
    return parser


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
