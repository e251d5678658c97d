"""``sid simulate``: the options of one run and those of a sweep are refused in the other mode, not ignored."""

from __future__ import annotations

import pytest

from sid.cli import main
from sid.cli.common import ExitCode

UNWRITABLE = ["--out", "/dev/null/sim"]  # were the option ignored, the run would stop at --out, at once


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["S1", "--seeds", "3"], "--seeds: applies to a --sweep only"),
        (["S1", "--workers", "2"], "--workers: applies to a --sweep only"),
        (["S1", "--ray", "local"], "--ray: applies to a --sweep only"),
        (["S1", "--sweep", "S2"], "SCENE: applies to one run, not to a --sweep"),
        (["--sweep", "S1", "--gif"], "--gif: applies to one run, not to a --sweep"),
        (["--sweep", "S1", "--still", "2"], "--still: applies to one run, not to a --sweep"),
        (["--sweep", "S1", "--seed", "4"], "--seed: applies to one run, not to a --sweep"),
    ],
)
def test_an_option_of_the_other_mode_is_refused(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """--seeds, --workers and --ray were ignored without --sweep; SCENE, --seed, --gif and --still with it."""
    assert main(["simulate", *argv, *UNWRITABLE]) == ExitCode.USAGE
    assert f"sid simulate: {message}" in capsys.readouterr().err


def test_defaults_are_not_taken_for_given_options(capsys: pytest.CaptureFixture[str]) -> None:
    """Neither mode is refused for the other's options left at their defaults: both reach the --out check."""
    for argv in (["S1"], ["--sweep", "S1"]):
        assert main(["simulate", *argv, *UNWRITABLE]) == ExitCode.USAGE
        assert "--out /dev/null/sim: cannot create the folder" in capsys.readouterr().err
