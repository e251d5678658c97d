"""The group detector's options (one per ``GroupParams`` field), shared by ``sid groups``, ``sid track``,
``sid detect`` and ``sid eval``, and the parameters file (``--params``) of the commands that run the detector."""

from __future__ import annotations

import argparse
import dataclasses
import re
from collections.abc import Callable

from sid.cli.common import plain_text
from sid.perception.groups import GROUP_METHODS, GroupParams
from sid.scenario.params_file import ParamsFile, load_params_file

__all__ = [
    "add_group_params",
    "add_json_lines_command",
    "add_params_file_option",
    "group_params_from",
    "params_file_from",
]


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
    add_params_file_option(parser, tracking=name == "track")
    add_group_params(parser)
    parser.set_defaults(func=run)
    return parser


def add_params_file_option(parser: argparse.ArgumentParser, tracking: bool) -> None:
    """``--params FILE``: a parameters file (``sid.scenario.params_file``); ``tracking``: whether the command runs
    the trackers (and so reads the file's tracking block)."""
    blocks = "groups and tracking blocks" if tracking else "groups block (a tracking block is for the trackers)"
    parser.add_argument(
        "--params",
        metavar="FILE",
        help=f"parameters file (YAML or JSON) whose {blocks} set the parameters; a group detector option given "
        'here as well wins over the file (docs/parameters.md, "Parameters file")',
    )


def params_file_from(args: argparse.Namespace) -> ParamsFile:
    """The parameters file ``--params`` names, or the defaults without one (ValueError naming the file and field)."""
    return ParamsFile() if args.params is None else load_params_file(args.params)


def add_group_params(parser: argparse.ArgumentParser) -> None:
    """One option per GroupParams field (--method, --group-price, --eps, ...); an option not given is None, so that
    ``group_params_from`` keeps the value of its base (the record's default, or a parameters file's)."""
    group = parser.add_argument_group("group detector parameters (metres, square metres, radians)")
    for field in dataclasses.fields(GroupParams):
        if field.name == "method":
            group.add_argument(
                "--method",
                "--group-method",
                dest="group_method",
                choices=GROUP_METHODS,
                help=f"{_field_help(field.name)} (default {field.default}; docs/groups.md)",
            )
            continue
        kind = int if isinstance(field.default, int) else float
        group.add_argument(
            "--" + field.name.replace("_", "-"),
            dest=f"group_{field.name}",
            type=kind,
            metavar="N" if kind is int else "X",
            help=f"{_field_help(field.name)} (default {field.default})",
        )


def group_params_from(args: argparse.Namespace, base: GroupParams | None = None) -> GroupParams:
    """``base`` (default: the record's defaults) with the fields given on the command line (ValueError for invalid
    values)."""
    given = {f.name: getattr(args, f"group_{f.name}") for f in dataclasses.fields(GroupParams)}
    return dataclasses.replace(base or GroupParams(), **{k: v for k, v in given.items() if v is not None})


def _field_help(name: str) -> str:
    """The first sentence of the field's entry in the GroupParams docstring."""
    doc = GroupParams.__doc__ or ""
    match = re.search(rf"^\s*{name}: (.+?\.)(?=\s+[A-Z0-9(`]|\s*$)", doc, flags=re.MULTILINE | re.DOTALL)
    return " ".join(match.group(1).split()) if match else name.replace("_", " ")
