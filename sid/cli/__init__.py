"""The ``sid`` command line: one subcommand per module in this package.

``common`` is the exception: the options and messages several subcommands share.
"""

from __future__ import annotations

import argparse
import importlib
import sys

# Each module provides ``add_parser(subparsers)``; the parser it adds sets ``func(args) -> int``.
COMMANDS: tuple[str, ...] = ("detect", "groups", "eval", "costmap", "plan", "demo", "compare", "reproduce", "bench")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="sid", description=__doc__.split("\n")[0].strip('"` '))
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"sid.cli.{name}").add_parser(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except KeyboardInterrupt:
        print("sid: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    raise SystemExit(main())
