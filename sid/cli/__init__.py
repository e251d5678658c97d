"""The ``sid`` command line: one subcommand per module in this package.

``common``, ``planning`` and ``grouping`` are the exceptions: the options, readers and messages several subcommands
share.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import warnings
from typing import TextIO

from sid import __version__
from sid.checks import limits_from_environment, use_limits
from sid.cli.common import (
    ExitCode,
    StandardOutputError,
    guarded_standard_output,
    report_standard_output,
    signals_as_interrupts,
)
from sid.cpu import keep_freed_memory
from sid.documents import InputWarning

__all__ = [
    "COMMANDS",
    "build_parser",
    "main",
    "DESCRIPTION",
    "EXIT_CODES",
]

# Each module provides ``add_parser(subparsers)``; the parser it adds sets ``func(args) -> int``.
COMMANDS: tuple[str, ...] = (
    "detect",
    "groups",
    "track",
    "eval",
    "costmap",
    "plan",
    "demo",
    "simulate",
    "compare",
    "reproduce",
    "bench",
    "model",
    "ros",
)


DESCRIPTION = (
    "sid: social interaction detection for robot navigation. See conversational groups with one RGB-D camera, build "
    "a social costmap and plan around them. 'sid COMMAND --help' describes each command."
)
EXIT_CODES = (
    "exit codes: "
    + ", ".join(
        f"{code.value} {text}"
        for code, text in (
            (ExitCode.OK, "done"),
            (ExitCode.FAILURE, "the run failed (e.g. a file could not be written)"),
            (ExitCode.USAGE, "bad command line or input"),
            (ExitCode.NO_PATH, "no path / goal not reached (plan, demo, compare, simulate, reproduce navigation)"),
            (ExitCode.MISSING_DEPENDENCY, "an optional package is missing (the message says how to install it)"),
            (ExitCode.DIFFERENT, "two pose models' results differ (model quantize, model compare)"),
        )
    )
    + "; 130 / 143 interrupted by Ctrl-C / SIGTERM."
)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser of every subcommand, or of ``command`` alone: each subcommand's module imports what it runs
    (onnxruntime, OMPL, the costmap, ...), so ``sid detect`` does not pay for the planners' imports at start-up."""
    parser = argparse.ArgumentParser(prog="sid", description=DESCRIPTION, epilog=EXIT_CODES)
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS if command is None else (command,):
        importlib.import_module(f"sid.cli.{name}").add_parser(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run one command; its exit code. SIGINT and SIGTERM stop it cleanly (exit 130 / 143: every file it wrote is
    whole), ``InputWarning``s print as one ``sid COMMAND [TASK]: warning: ...`` line, and a standard output that
    cannot be written ends it the same way in every command (``report_standard_output``)."""
    argv = sys.argv[1:] if argv is None else argv
    known = argv[0] if argv and argv[0] in COMMANDS else None  # else: help, or an error listing every command
    with guarded_standard_output():  # --help writes there too
        try:
            try:
                args = build_parser(known).parse_args(argv)
            finally:  # after --help (SystemExit) as well: a failure is reported here, not at exit
                sys.stdout.flush()
        except StandardOutputError as exc:
            return report_standard_output(f"sid {known}" if known else "sid", exc)
    command = " ".join(["sid", args.command, *([args.task] if getattr(args, "task", None) else [])])  # sid eval crowd
    try:
        in_force = limits_from_environment()  # $SID_LIMITS, read here once; a malformed one is said before any work
    except ValueError as exc:
        print(f"{command}: {exc}", file=sys.stderr)
        return ExitCode.USAGE
    default_show = warnings.showwarning

    def show(
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: TextIO | None = None,
        line: str | None = None,
    ) -> None:
        if issubclass(category, InputWarning):
            print(f"{command}: warning: {message}", file=sys.stderr)
        else:
            default_show(message, category, filename, lineno, file, line)

    keep_freed_memory()  # numpy's image-sized temporaries reuse heap memory instead of new mappings (sid.cpu)
    with use_limits(in_force), warnings.catch_warnings(), signals_as_interrupts(), guarded_standard_output():
        warnings.showwarning = show
        try:
            code = int(args.func(args) or 0)
            sys.stdout.flush()  # here, where a failure is reported, not at exit
            return code
        except KeyboardInterrupt as exc:
            print(f"{command}: interrupted", file=sys.stderr)
            return 128 + int(getattr(exc, "signal_number", 2))
        except StandardOutputError as exc:  # closed, full, or a reader that went away (| head)
            return report_standard_output(command, exc)


if __name__ == "__main__":
    raise SystemExit(main())
