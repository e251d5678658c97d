"""Bad input, round three (issue 29, sizes and numbers): every size bounded before it is allocated, every accepted
number safe to the end of the pipeline, degenerate geometry handled as geometry, errors short."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from sid.cli import main
from tests.conftest import REPO_ROOT

EXAMPLE = REPO_ROOT / "examples" / "conversation.json"


def scenario(tmp_path: Path, change: dict | None = None, **sections: object) -> str:
    """The example scenario with top-level sections replaced (``sections``) and dotted fields set (``change``)."""
    data = json.loads(EXAMPLE.read_text()) | sections
    for dotted, value in (change or {}).items():
        *parents, last = dotted.split(".")
        node = data
        for key in parents:
            node = node.setdefault(key, {}) if isinstance(node, dict) else node[int(key)]
        node[last if isinstance(node, dict) else int(last)] = value
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    return str(path)


def error_line(capsys: pytest.CaptureFixture[str]) -> str:
    """The one stderr line of a refused run (no traceback)."""
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.count("\n") == 1, err
    return err.strip()


# --- degenerate geometry -------------------------------------------------------------------------------------

ON_ONE_SPOT = [  # three people on one spot facing apart, a fourth nearby: the grouping forms a zone of no area
    {"id": 1, "x": 4.0, "y": -0.3, "theta": 1.5708},
    {"id": 2, "x": 4.0, "y": -0.3, "theta": -0.9},
    {"id": 3, "x": 4.0, "y": -0.3, "theta": -0.96},
    {"id": 4, "x": 4.0, "y": -0.3, "theta": 1.5708},
]


@pytest.mark.parametrize("method", ["ospace", "gcff", "rays", "paper"])
@pytest.mark.parametrize("command", ["costmap", "plan"])
def test_people_on_one_spot_are_geometry(tmp_path, capsys, command, method):
    path = scenario(tmp_path, people=ON_ONE_SPOT, groups={"method": method})
    extra = ["--planner", "grid"] if command == "plan" else []
    assert main([command, path, *extra, "--out", str(tmp_path / "out")]) == 0, capsys.readouterr().err
    assert (tmp_path / "out" / ("plan.png" if command == "plan" else "costmap.png")).is_file()
