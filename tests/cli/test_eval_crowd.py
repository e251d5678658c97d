"""``sid eval crowd`` end to end on trajectory sets written here, and its refusals."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

from sid.cli import main
from tests.experiments.trajectory_files import pair_and_strangers

pytestmark = pytest.mark.skipif(importlib.util.find_spec("motmetrics") is None, reason="py-motmetrics not installed")


def test_the_table_has_a_row_per_set_with_both_group_trackers(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    folders = [str(pair_and_strangers(tmp_path / name, frames=20)) for name in ("north", "south")]
    assert main(["eval", "crowd", *folders]) == 0
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    assert lines[0].split()[:5] == ["set", "frames", "MOTA", "IDF1", "IDsw"] and "coherent" in lines[0]
    assert [line.split()[:2] for line in lines[1:]] == [["north", "20"], ["south", "20"]]
    # the progress, line by line off a terminal: six passes over each set's 20 frames, one count per set
    progress = [line for line in captured.err.splitlines() if line.startswith("crowd: ")]
    assert len(progress) == 22 and progress[-1].startswith("crowd: 120/120 (100 %)")
    assert progress[-1].endswith("south: scoring the reference")


def test_a_long_set_name_keeps_the_columns(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    # The name column was 12 characters wide: a longer folder name pushed its row's numbers out of their columns.
    folders = [str(pair_and_strangers(tmp_path / name, frames=12)) for name in ("a", "students003_left_half")]
    assert main(["eval", "crowd", *folders]) == 0
    header, *rows = capsys.readouterr().out.splitlines()
    assert len({line.index(" | ") for line in (header, *rows)}) == 1
    assert all(row.index(" | ") == header.index(" | ") for row in rows)


def test_json_holds_the_settings_and_every_score(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    folder = pair_and_strangers(tmp_path / "scene", frames=20)
    argv = ["eval", "crowd", str(folder), "--json", "--rate", "5", "--noise", "0.05", "--view=-2,0.3,0", "--fov=60"]
    assert main(argv) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["settings"]["replay"]["rate"] == 5.0 and result["settings"]["replay"]["noise"] == 0.05
    scene = result["sets"]["scene"]
    assert scene["frames"] == 39  # 19 steps of 0.4 s (read from the annotations) at 5 Hz, both ends
    assert main([*argv, "--interval", "0.2"]) == 0  # the set's 19 steps taken as 0.2 s each
    assert json.loads(capsys.readouterr().out)["sets"]["scene"]["frames"] == 20
    assert {"mota", "idf1", "id_switches", "id_switches_per_100_tracks"} <= set(scene["people"])
    assert set(scene["groups"]) == set(scene["coherent_motion"]) == {"gmitre", "groups_T2/3", "groups_T1"}


def test_cross_validation_prints_one_row_per_stage_and_held_out_set(
    tmp_path: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    from sid.cli import eval_crowd

    small = {
        "tracker": {"timeout": (1.0, 1.5)},
        "groups": {"walk_distance": (1.5,)},
        "coherent": {"share": (0.8,)},
        "reporting": {"report_timeout": (0.4, 1.5)},
    }
    monkeypatch.setattr(eval_crowd, "DEFAULT_GRID", small)
    folders = [str(pair_and_strangers(tmp_path / name, frames=12)) for name in ("a", "b")]
    assert main(["eval", "crowd", *folders, "--cross-validate"]) == 0
    out = capsys.readouterr().out
    rows = [line.split()[:2] for line in out.splitlines()[1:]]
    assert rows == [[s, stage] for s in ("a", "b") for stage in ("tracker", "groups", "coherent", "reporting")]
    assert main(["eval", "crowd", *folders, "--cross-validate", "--workers", "2"]) == 0
    assert capsys.readouterr().out == out  # the same table from two worker processes


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--rate", "0"], "replay: rate must be"),
        (["--miss-rate", "1"], "replay: miss_rate must be"),
        (["--fov", "400", "--view", "0,0,0"], "fov"),
        (["--interval", "0"], "trajectories: interval must be"),
        (["--workers", "2"], "--workers spreads the cross-validation's grid points: give --cross-validate too"),
    ],
)
def test_bad_settings_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture, argv: list[str], message: str) -> None:
    folder = pair_and_strangers(tmp_path / "scene", frames=5)
    assert main(["eval", "crowd", str(folder), *argv]) == 2
    assert message in capsys.readouterr().err


def test_bad_folders_are_one_line_naming_the_problem(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    assert main(["eval", "crowd", str(tmp_path / "nowhere")]) == 2
    assert (
        capsys.readouterr().err.strip()
        == f"sid eval crowd: {tmp_path / 'nowhere'}: no obsmat.txt (a trajectory set holds obsmat.txt and groups.txt)"
    )
    one, other = pair_and_strangers(tmp_path / "a" / "zara", 5), pair_and_strangers(tmp_path / "b" / "zara", 5)
    assert main(["eval", "crowd", str(one), str(other)]) == 2
    assert "two sets are named 'zara'" in capsys.readouterr().err


def test_a_view_that_is_not_three_numbers_is_a_usage_error(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["eval", "crowd", str(tmp_path), "--view", "1,2"])
    assert exit_.value.code == 2 and "expected X,Y,YAW (metres, metres, degrees), got '1,2'" in capsys.readouterr().err
