"""``sid eval tracking`` end to end on a short run, and its refusals."""

from __future__ import annotations

import importlib.util
import json

import pytest

from sid.cli import main

pytestmark = pytest.mark.skipif(importlib.util.find_spec("motmetrics") is None, reason="py-motmetrics not installed")

SHORT = ["eval", "tracking", "--sequences", "crossing_walkers", "--frames", "18", "--flicker-frames", "18"]


def test_the_table_names_every_score(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([*SHORT, "--table"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:4] == ["sequence", "MOTA", "IDF1", "IDsw"]
    assert lines[1].startswith("crossing_walkers") and lines[2].startswith("overall")
    assert lines[3].startswith("flicker (S5, 3 frame pairs")


def test_json_by_default(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(SHORT) == 0
    result = json.loads(capsys.readouterr().out)
    assert set(result) == {"settings", "sequences", "overall", "flicker"}
    assert result["sequences"]["crossing_walkers"]["frames"] == 18


@pytest.mark.parametrize(
    ("option", "message"),
    [
        (["--fps", "0"], "fps must be a positive number"),
        (["--frames", "0"], "frames must be a whole number >= 1"),
        # "overall" counted a repeated sequence's frames twice
        (["--sequences", "walking_pairs", "walking_pairs"], "sequence walking_pairs is given twice"),
    ],
)
def test_bad_settings_are_refused(option: list[str], message: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["eval", "tracking", *option]) == 2
    assert message in capsys.readouterr().err
