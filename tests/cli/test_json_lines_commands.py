"""``sid groups`` and ``sid track``: the command and ``process`` (what the tests and the fuzzers call) are one path."""

from __future__ import annotations

import importlib
import json
from pathlib import Path

import pytest

from sid.cli import main

PAIR = [{"id": 1, "x": 0.0, "y": 0.0, "theta": 0.0}, {"id": 2, "x": 1.2, "y": 0.0, "theta": 3.14159}]


@pytest.mark.parametrize(
    ("command", "lines"),
    [
        ("groups", [{"frame": 0, "people": PAIR}]),
        ("track", [{"timestamp": 0.1 * k, "people": PAIR} for k in range(3)]),
    ],
)
def test_the_command_runs_through_process(command: str, lines: list[dict], tmp_path: Path, monkeypatch, capsys) -> None:
    # run built its own handler beside process's, so a test of process did not test the command.
    module = importlib.import_module(f"sid.cli.{command}")
    calls = []
    original = module.process

    def spy(*args, **kwargs):  # type: ignore[no-untyped-def]
        calls.append(args)
        return original(*args, **kwargs)

    monkeypatch.setattr(module, "process", spy)
    path = tmp_path / "lines.jsonl"
    path.write_text("".join(json.dumps(line) + "\n" for line in lines))
    assert main([command, str(path)]) == 0
    out = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert len(calls) == 1 and len(out) == len(lines)
    found = out[-1]["groups"] if command == "groups" else out[-1]["people"]  # the pair; two confirmed tracks
    assert len(found) == (1 if command == "groups" else 2)
