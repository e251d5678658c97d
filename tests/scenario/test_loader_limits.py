"""Scenario limits and map checks (issue 15): refused before allocation, raised with SID_LIMITS; a static map on
other cells is resampled with a warning, a rotated one refused."""

from __future__ import annotations

import json

import pytest

from sid.checks import Limits, use_limits
from sid.cli import main
from sid.documents import InputWarning
from sid.scenario.loader import ScenarioError, load_scenario
from tests.conftest import REPO_ROOT

MALFORMED = REPO_ROOT / "tests" / "fixtures" / "malformed" / "scenario"


def test_raised_limits_let_a_larger_map_load():
    with pytest.raises(ScenarioError, match="map_cells"):
        load_scenario(MALFORMED / "map_1000m.json")
    with use_limits(Limits(map_cells=400_000_000)):
        assert load_scenario(MALFORMED / "map_1000m.json").grid.shape == (20000, 20000)  # nothing allocated yet


def test_people_limit_counts_before_parsing_them():
    with use_limits(Limits(people=2)), pytest.raises(ScenarioError, match=r"people: 4 people is more than the limit"):
        load_scenario(REPO_ROOT / "examples" / "conversation.json")


@pytest.mark.parametrize("field", ["lidar.range_max", "layers.obstacle.raytrace_max_range"])
def test_a_range_near_the_largest_float_is_refused_by_the_scan_limit(tmp_path, field):
    # 1.7e308 m / 0.05 m is infinite: math.ceil raised OverflowError, a traceback instead of the limit's message.
    data = json.loads((REPO_ROOT / "examples" / "conversation.json").read_text())
    section, *rest = field.split(".")
    node = data.setdefault(section, {})
    for key in rest[:-1]:
        node = node.setdefault(key, {})
    node[rest[-1]] = 1.7e308
    (tmp_path / "s.json").write_text(json.dumps(data))
    with pytest.raises(ScenarioError, match=r"720 beams x inf cells of range \(1.7e\+308 m at 0.05 m\).*scan_cells"):
        load_scenario(tmp_path / "s.json")


def _with_static_map(tmp_path, resolution: float) -> str:
    (tmp_path / "room.pgm").write_bytes(b"P5\n20 16\n255\n" + bytes([254] * 320))
    (tmp_path / "room.yaml").write_text(
        f"image: room.pgm\nresolution: {resolution}\norigin: [-1.0, -4.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.25\n"
    )
    data = json.loads((REPO_ROOT / "examples" / "conversation.json").read_text())
    data["static_map"] = "room.yaml"
    (tmp_path / "s.json").write_text(json.dumps(data))
    return str(tmp_path / "s.json")


def test_a_coarser_static_map_is_resampled_with_a_warning(tmp_path):
    with pytest.warns(InputWarning, match=r"room.yaml: 0.5 m cells sampled onto the scenario's 0.05 m cells"):
        assert load_scenario(_with_static_map(tmp_path, 0.5)).grid.resolution == 0.05


def test_the_resampling_warning_is_one_line_of_the_command(tmp_path, capsys):
    assert main(["costmap", _with_static_map(tmp_path, 0.5), "--out", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err.splitlines()
    assert [line for line in err if "warning" in line] == [
        f"sid costmap: warning: static_map: {tmp_path / 'room.yaml'}: 0.5 m cells sampled onto the scenario's "
        "0.05 m cells (each takes the most occupied map cell it overlaps)"
    ]


def test_a_static_map_shifted_by_part_of_a_cell_is_said(tmp_path):
    scenario = _with_static_map(tmp_path, 0.05)
    path = tmp_path / "room.yaml"
    path.write_text(path.read_text().replace("origin: [-1.0,", "origin: [-0.975,", 1))
    with pytest.warns(InputWarning, match=r"0.05 m cells, shifted by part of a cell, sampled onto the scenario's"):
        load_scenario(scenario)


def test_a_static_map_on_the_same_cells_gives_no_warning(tmp_path, recwarn):
    load_scenario(_with_static_map(tmp_path, 0.05))
    assert not [w for w in recwarn if issubclass(w.category, InputWarning)]
