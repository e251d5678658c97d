"""Progress on stderr: a bar with an estimate of the time left on a terminal, plain lines anywhere else."""

from __future__ import annotations

import io
import re

from sid.experiments.progress import ProgressBar, _seconds
from sid.experiments.simulate.loop import RunOptions
from sid.experiments.simulate.run import write_run
from tests.experiments.simulate.tiny import tiny_world


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_off_a_terminal_one_line_per_tenth_and_no_redraws() -> None:
    stream = io.StringIO()
    bar = ProgressBar("work", stream)
    for done in range(601):
        bar(done, 600, f"item {done}")
    lines = stream.getvalue().splitlines()
    assert "\r" not in stream.getvalue() and len(lines) == 11
    assert lines[0].startswith("work: 0/600 (0 %)") and lines[-1].startswith("work: 600/600 (100 %)")
    assert all(re.search(r"about \d+(\.\d)? s left", line) for line in lines[1:-1])


def test_off_a_terminal_the_time_left_is_estimated_from_a_tenth_of_the_work_on() -> None:
    """The first line, after one item of 87 000, said "about 9132 s left" for a run of 32 s."""
    stream = io.StringIO()
    bar = ProgressBar("work", stream)
    for done in (1, 50, 100):
        bar(done, 1000, "item")
    assert [("left" in line) for line in stream.getvalue().splitlines()] == [False, True]


def test_on_a_terminal_a_bar_with_the_count_and_the_time_left() -> None:
    stream = Terminal()
    bar = ProgressBar("work", stream)
    for done in range(51):
        bar(done, 50, "item")
    text = re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]", "", stream.getvalue())  # colours and cursor codes aside
    assert "50/50" in text and "left" in text and text.endswith("\n")  # the bar's line ended


def test_a_new_stage_starts_a_new_count() -> None:
    stream = io.StringIO()
    bar = ProgressBar("tracking", stream)
    for stage in ("a", "b"):
        for done in range(1, 11):
            bar(done, 10, stage)
    lines = stream.getvalue().splitlines()
    assert [line for line in lines if "10/10" in line] == [
        "tracking: 10/10 (100 %), 0.0 s, a",
        "tracking: 10/10 (100 %), 0.0 s, b",
    ]


def test_short_runs_read_in_tenths_of_a_second() -> None:
    """A run of a few seconds said "0 s, about 0 s left" at every tenth."""
    assert [_seconds(s) for s in (0.04, 0.44, 9.9, 9.96, 56.4)] == ["0.0 s", "0.4 s", "9.9 s", "10 s", "56 s"]


def test_a_simulation_that_reaches_its_goal_early_ends_its_count_there() -> None:
    """The count goes to the steps run, not on to the time limit's (it stopped at 203/600, then jumped to 600/600)."""
    stream = io.StringIO()
    world = tiny_world(robot={"start": [0.0, 0.0, 0.0], "goal": [1.0, 0.0, 0.0], "radius": 0.25})
    record = write_run(world, RunOptions(perception="exact"), None, progress=ProgressBar("simulate", stream))
    assert record["success"]
    lines = stream.getvalue().splitlines()
    steps = int(re.match(r"simulate: (\d+)/\1 \(100 %\)", lines[-1]).group(1))
    assert 0 < steps < 100 and lines[-1].endswith(record["reason"])
    assert all("/100 " in line for line in lines[:-1])  # the time limit's 100 steps while it ran
