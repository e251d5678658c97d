"""Fuzzing every command's argument parsing (issue 15): any command line either parses or ends in argparse's usage
error (exit 2), and the commands that validate their numbers before any work refuse bad ones in one line (exit 2),
never with a traceback or a hang."""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import tempfile
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sid.cli import build_parser, main
from sid.cli.common import ExitCode
from tests.conftest import REPO_ROOT
from tests.fuzz.guards import bounded

# Values as a user may type them: numbers at every edge, negatives, words, empty, paths and globs.
TOKENS = st.sampled_from(
    ["0", "-1", "1", "2", "1e9", "99999999999999999999", "nan", "inf", "-inf", "0.5", "1/0", "", "x", "-", "--",
     "/nonexistent", "*", "S1", "grid", "synthetic:S1", "\x00", "é"]
) | st.text(max_size=6)  # fmt: skip


def _subcommands(parser: argparse.ArgumentParser, prefix: tuple[str, ...] = ()) -> dict[tuple[str, ...], list[str]]:
    """Every leaf subcommand (e.g. ("eval", "fformation")) with its option strings."""
    out: dict[tuple[str, ...], list[str]] = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                out |= _subcommands(sub, (*prefix, name))
    if not out and prefix:
        out[prefix] = [s for a in parser._actions for s in a.option_strings if s not in ("-h", "--help")]
    return out


SUBCOMMANDS = _subcommands(build_parser())


@st.composite
def command_lines(draw: st.DrawFn) -> list[str]:
    """A subcommand followed by a few of its options and arbitrary tokens, in any order."""
    command = draw(st.sampled_from(sorted(SUBCOMMANDS)))
    options = SUBCOMMANDS[command]
    words = (
        draw(st.lists(st.sampled_from(options) | TOKENS, max_size=6)) if options else draw(st.lists(TOKENS, max_size=3))
    )
    return [*command, *words]


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(command_lines())
def test_any_command_line_parses_or_gets_a_usage_error(argv):
    parser = build_parser()
    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()), bounded():
        try:
            parser.parse_args(argv)
        except SystemExit as exc:
            assert exc.code == 2


def test_every_command_is_fuzzed():
    assert {command[0] for command in SUBCOMMANDS} >= {
        "detect", "groups", "eval", "costmap", "plan", "demo", "compare", "reproduce", "bench", "model"
    }  # fmt: skip


NUMBER_TEXT = st.sampled_from(["0", "-1", "1e9", "nan", "inf", "-inf", "1e-300", "99999999999999999999", "abc", "0.3"])


def _run(argv: list[str]) -> tuple[int, str]:
    """``sid ARGV`` in this process: its exit code (argparse's usage error included) and its stderr."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()), bounded():
        try:
            code = main(argv)
        except SystemExit as exc:
            code = int(exc.code or 0)
    return code, err.getvalue()


def _walled_in(folder: Path) -> Path:
    """The example scenario with its goal inside a box: every plan ends in "no path" before any search."""
    data = json.loads((REPO_ROOT / "examples" / "conversation.json").read_text())
    data["obstacles"].append({"type": "box", "min": [7.5, -0.5], "max": [8.5, 0.5]})
    path = folder / "walled.json"
    path.write_text(json.dumps(data))
    return path


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.fixed_dictionaries(
        {},
        optional={
            "--time": NUMBER_TEXT,
            "--seed": NUMBER_TEXT,
            "--iterations": NUMBER_TEXT,
            "--cost-weight": NUMBER_TEXT,
            "--planner": st.sampled_from(["grid", "rrtconnect", "prm", ""]),
        },
    )
)
def test_plan_options_are_refused_or_end_in_no_path(options):
    with tempfile.TemporaryDirectory() as folder:
        argv = ["plan", str(_walled_in(Path(folder))), "--out", str(Path(folder) / "out")]
        code, err = _run(argv + [word for pair in options.items() for word in pair])
    assert code in (ExitCode.USAGE, ExitCode.NO_PATH) and "Traceback" not in err, err
    assert code == ExitCode.USAGE or err.startswith("sid plan: no path:"), err
    assert len(err.strip().splitlines()) == 1 or "usage:" in err


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.fixed_dictionaries(
        {},
        optional={
            "--eps": NUMBER_TEXT,
            "--min-samples": NUMBER_TEXT,
            "--ray-length": NUMBER_TEXT,
            "--spread-threshold": NUMBER_TEXT,
            "--facing-tolerance": NUMBER_TEXT,
        },
    )
)
def test_group_options_are_refused_in_one_line_or_used(options):
    with tempfile.TemporaryDirectory() as folder:
        frames = Path(folder) / "frames.jsonl"
        frames.write_text(
            '{"frame": 0, "people": [{"id": 1, "x": 0, "y": 0, "theta": 0}, {"id": 2, "x": 1, "y": 0}]}\n'
        )
        code, err = _run(["groups", str(frames)] + [word for pair in options.items() for word in pair])
    assert code in (0, 2) and "Traceback" not in err, err
    if code == 2 and "usage:" not in err:
        assert len(err.strip().splitlines()) == 1, err


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.fixed_dictionaries(
        {},
        optional={
            "--frames": NUMBER_TEXT,
            "--camera-height": NUMBER_TEXT,
            "--camera-tilt": NUMBER_TEXT,
            "--keypoint-threshold": NUMBER_TEXT,
            "--threads": NUMBER_TEXT,
        },
    )
)
def test_detect_options_are_refused_in_one_line_or_used(options):
    options.setdefault("--frames", "1")
    if options["--frames"] not in ("0", "1", "-1", "abc", "nan"):
        options["--frames"] = "1"  # keep a run short: one synthetic frame
    code, err = _run(["detect", "--source", "synthetic:S1"] + [word for pair in options.items() for word in pair])
    assert code in (0, 2) and "Traceback" not in err, err
