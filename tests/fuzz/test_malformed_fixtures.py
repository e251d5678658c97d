"""The malformed inputs that found bugs (issue 15), kept in tests/fixtures/malformed: each ends in one line naming
the file, the field, the value and the limit, with exit code 2, before anything is allocated for it."""

from __future__ import annotations

import json

import pytest

from sid.cli import main
from sid.perception.camera import Calibration
from tests.conftest import REPO_ROOT
from tests.fuzz.guards import bounded

MALFORMED = REPO_ROOT / "tests" / "fixtures" / "malformed"

SCENARIOS = {  # file -> words the one-line error must hold
    "lidar_beams_1e9.json": ["lidar.beams: 1,000,000,000 beams", "limit of 100,000", "SID_LIMITS=lidar_beams="],
    "lidar_range_1e6.json": ["lidar: 720 beams x 20,000,000 cells of range", "scan_cells"],
    "map_1000m.json": ["map.size: 20000 x 20000 = 400,000,000 cells", "limit of 4,000,000 cells"],
    "map_resolution_1e-5.json": ["map.size: 1e+06 x 800000", "map_cells"],
    "map_size_1e6.json": ["map.size: 2e+07 x 2e+07", "map_cells"],
    "inflation_radius_1e6.json": ["layers.inflation.inflation_radius: 1e+06 m", "diagonal (12.8062 m)"],
    "people_4000.json": ["people: 4,000 people", "limit of 100 people"],
    "wall_1e12.json": ["obstacles[5].points[0]: (-1e+12, 0)", "diagonal"],
    "rotated_static_map.json": ["static_map:", "rotated.yaml: origin yaw 0.7 rad"],
    "binary_static_map.json": ["binary.yaml: cannot read map YAML: byte 0xfe", "not UTF-8"],
    "huge_static_map.json": ["huge.pgm", "100000 x 100000 = 10,000,000,000 pixels is more than the limit"],
    "deep.json": ["deep.json: cannot read scenario file: nested too deeply"],
    "garbage.json": ["garbage.json: cannot read scenario file: byte 0x89 at offset 0"],
    "binary.yaml": ["binary.yaml: cannot read scenario file: byte 0x80"],
}


@pytest.mark.parametrize("name", SCENARIOS)
def test_malformed_scenario_is_one_line_naming_file_and_field(name, tmp_path, capsys):
    path = MALFORMED / "scenario" / name
    with bounded():
        assert main(["costmap", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and err.startswith(f"sid costmap: {path}: "), err
    for words in SCENARIOS[name]:
        assert words in err, err
    assert not (tmp_path / "out").exists()


def test_every_scenario_fixture_is_checked():
    assert {p.name for p in (MALFORMED / "scenario").iterdir()} == set(SCENARIOS)


def test_deep_and_oversized_json_lines_are_skipped_with_their_number(capsys):
    for name, problem in [("deep.jsonl", "not valid JSON (nested too deeply)"), ("crowd.jsonl", "1,000 people")]:
        with bounded():
            assert main(["groups", str(MALFORMED / "groups" / name)]) == 2  # its one line refused: none good
        err = capsys.readouterr().err
        assert err.startswith("sid groups: line 1: ") and problem in err, err


def test_a_line_that_is_not_utf8_is_skipped_and_the_next_is_kept(capsys):
    assert main(["groups", str(MALFORMED / "groups" / "latin1_then_good.jsonl")]) == 0
    captured = capsys.readouterr()
    assert "line 1: not UTF-8 text (byte 0xe9" in captured.err
    assert [json.loads(line)["frame"] for line in captured.out.splitlines()] == [1]


@pytest.mark.parametrize(
    ("name", "field"),
    [
        ("fx_null.json", "fx"),
        ("fx_list.json", "fx"),
        ("width_null.json", "width"),
        ("depth_scale_list.json", "depth_scale_m"),
        ("color_abc.json", "color"),
        ("garbage.json", "not UTF-8"),
    ],
)
def test_malformed_calibration_names_file_and_field(name, field):
    path = MALFORMED / "calibration" / name
    with pytest.raises(ValueError) as error:
        Calibration.from_json(path)
    assert str(path) in str(error.value) and field in str(error.value)
