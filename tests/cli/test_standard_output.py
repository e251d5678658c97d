"""A standard output that cannot be written (issue 29) ends every command the same way: quietly with exit 0 when
its reader went away (a broken pipe, ``| head -1``), and with ``cannot write standard output (REASON)`` and exit 1
when it is full (``> /dev/full``) or closed (``>&-``)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import REPO_ROOT

SCENARIO = str(REPO_ROOT / "examples" / "conversation.json")
PEOPLE = [{"id": 1, "x": 0.0, "y": 0.0, "theta": 0.0}, {"id": 2, "x": 1.0, "y": 0.0, "theta": 3.1}]


def _commands(folder: Path) -> dict[str, list[str]]:
    """A run of each command that writes to standard output, on small inputs."""
    groups = folder / "groups.jsonl"
    groups.write_text("".join(json.dumps({"frame": n, "people": PEOPLE}) + "\n" for n in range(50)))
    track = folder / "track.jsonl"
    track.write_text("".join(json.dumps({"timestamp": n / 10, "people": PEOPLE}) + "\n" for n in range(50)))
    return {
        "groups": ["groups", str(groups)],
        "track": ["track", str(track)],
        "detect": ["detect", "--source", "synthetic:S1", "--frames", "2"],
        "costmap": ["costmap", SCENARIO, "--out", str(folder / "costmap")],
    }


def _run(argv: list[str], stdout: int | None, *, close_stdout: bool = False) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "sid", *argv],
        cwd=REPO_ROOT,
        stdout=stdout,
        stderr=subprocess.PIPE,
        timeout=300,
        pass_fds=() if stdout is None or stdout < 0 else (stdout,),
        preexec_fn=(lambda: os.close(1)) if close_stdout else None,
    )


@pytest.mark.parametrize("command", ["groups", "track", "detect", "costmap"])
def test_a_reader_that_went_away_ends_the_run_quietly(tmp_path, command):
    read, write = os.pipe()
    os.close(read)  # the reader is gone before the first line: every write is a broken pipe
    try:
        done = _run(_commands(tmp_path)[command], write)
    finally:
        os.close(write)
    assert (done.returncode, done.stderr.decode()) == (0, "")


@pytest.mark.parametrize("command", ["groups", "track", "detect", "costmap"])
def test_a_full_standard_output_is_named_as_such(tmp_path, command):
    with open("/dev/full", "wb") as full:
        done = _run(_commands(tmp_path)[command], full.fileno())
    assert done.returncode == 1  # a failed run
    assert f"sid {command}: cannot write standard output (No space left on device)" in done.stderr.decode()
    assert "Traceback" not in done.stderr.decode() and "cannot read" not in done.stderr.decode()


@pytest.mark.parametrize("command", ["groups", "detect"])
def test_a_closed_standard_output_is_named_as_such(tmp_path, command):
    done = _run(_commands(tmp_path)[command], None, close_stdout=True)
    assert done.returncode == 1  # a failed run
    assert f"sid {command}: cannot write standard output (it is closed)" in done.stderr.decode()
    assert "Traceback" not in done.stderr.decode()


def test_help_is_written_under_the_same_rules():
    with open("/dev/full", "wb") as full:
        done = _run(["groups", "--help"], full.fileno())
    assert (done.returncode, done.stderr.decode()) == (
        1,
        "sid groups: cannot write standard output (No space left on device)\n",
    )
    read, write = os.pipe()
    os.close(read)
    try:
        done = _run(["--help"], write)
    finally:
        os.close(write)
    assert (done.returncode, done.stderr.decode()) == (0, "")
