"""Command-line conventions every ``sid`` command keeps: ``--version``; plain-text help whose defaults are the values
used; a default output folder ``./sid-COMMAND`` for every command that writes files; one meaning per exit code."""

from __future__ import annotations

import argparse
import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from sid import __version__
from sid.cli import build_parser, main
from sid.cli.common import ExitCode
from tests.conftest import REPO_ROOT


def _parsers(parser: argparse.ArgumentParser, name: str = "sid") -> Iterator[tuple[str, argparse.ArgumentParser]]:
    yield name, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub, subparser in action.choices.items():
                yield from _parsers(subparser, f"{name} {sub}")


PARSERS = dict(_parsers(build_parser()))


def _options(parser: argparse.ArgumentParser) -> Iterator[tuple[argparse.Action, str]]:
    """Each option with its help as printed (``%(default)s`` filled in)."""
    formatter = parser._get_formatter()
    for action in parser._actions:
        if action.option_strings and action.help not in (None, argparse.SUPPRESS):
            yield action, formatter._expand_help(action)


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as stopped:
        main(["--version"])
    assert stopped.value.code == 0 and capsys.readouterr().out == f"sid {__version__}\n"


@pytest.mark.parametrize("name", PARSERS)
def test_help_is_plain_text(name: str) -> None:
    text = PARSERS[name].format_help()
    assert "`" not in text and ":class:" not in text and ":func:" not in text, text


@pytest.mark.parametrize("name", PARSERS)
def test_the_default_a_help_names_is_the_value_used(name: str) -> None:
    """ "default X" / "default: X" in an option's help is the option's real default (a ``set_defaults`` elsewhere
    must not leave the help behind)."""
    for action, text in _options(PARSERS[name]):
        default = action.default
        if isinstance(default, bool) or not isinstance(default, str | int | float):
            continue  # flags, lists and paths say their defaults in words
        for said in re.findall(r"\bdefault:? ([^\s;,)]+)", text):
            said = said.removeprefix("./")
            if isinstance(default, str):
                assert said == default, f"{name} {action.option_strings[-1]}: help says {said}, default {default}"
            else:
                assert float(said) == default, (
                    f"{name} {action.option_strings[-1]}: help says {said}, default {default}"
                )


WRITERS = ("demo", "plan", "costmap", "simulate", "compare", "reproduce table1", "reproduce navigation", "bench")
"""The commands that write files (sid detect writes them only when asked, with --out)."""


@pytest.mark.parametrize("command", WRITERS)
def test_every_command_that_writes_files_has_a_default_folder_shown_in_its_help(command: str) -> None:
    parser = PARSERS[f"sid {command}"]
    (out,) = (action for action in parser._actions if "--out" in action.option_strings)
    folder = f"sid-{command.split()[0]}"
    assert out.default == folder and not out.required
    assert f"(default: ./{folder})" in " ".join(parser.format_help().split())


def test_each_exit_code_has_one_meaning_listed_in_the_help_and_the_readme() -> None:
    codes = [code.value for code in ExitCode]
    assert len(set(codes)) == len(codes) and codes == [0, 1, 2, 3, 4, 5]
    epilog = " ".join(build_parser().format_help().split())
    readme = (REPO_ROOT / "README.md").read_text()
    section = readme.split("## Exit codes", 1)[1].split("\n## ", 1)[0]
    for code in ExitCode:
        assert f"{code.value} " in epilog
        assert re.search(rf"^\| {code.value} \|", section, flags=re.MULTILINE), (
            f"README lists no exit code {code.value}"
        )


def test_the_help_names_the_commands_that_exit_3_as_the_readme_does() -> None:
    """README's row for exit 3 names ``sid compare`` (a scenario's task found impossible); the epilog left it out."""
    epilog = " ".join(build_parser().format_help().split())
    help_commands = set(re.search(r"3 no path / goal not reached \(([^)]*)\)", epilog)[1].split(", "))
    readme = (REPO_ROOT / "README.md").read_text()
    row = re.search(r"^\| 3 \|(.*)$", readme, flags=re.MULTILINE)[1]
    commands = {name.removeprefix("sid ") for name in PARSERS}
    readme_commands = {c for c in re.findall(r"`(?:sid )?([a-z ]+)`", row) if c in commands}
    assert help_commands == readme_commands == {"plan", "demo", "compare", "simulate", "reproduce navigation"}


def test_detect_group_method_help_names_every_method() -> None:
    """``sid detect --group-method`` listed ospace, rays and paper, not gcff."""
    from sid.perception.groups import GROUP_METHODS

    (action,) = [a for a in PARSERS["sid detect"]._actions if "--group-method" in a.option_strings]
    assert all(method in (action.help or "") for method in GROUP_METHODS)


def test_a_run_that_cannot_write_its_files_fails_with_exit_1(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A failure, not bad input: the folder passes the check, but a folder stands where costmap.png goes."""
    (tmp_path / "costmap.png").mkdir()
    scenario = str(REPO_ROOT / "examples" / "conversation.json")
    assert main(["costmap", scenario, "--out", str(tmp_path)]) == ExitCode.FAILURE
    assert "sid costmap: " in capsys.readouterr().err
