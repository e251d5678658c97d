"""Scenario files: the documented fields and defaults, and errors that name the offending field."""

from __future__ import annotations

import copy
import json
import math
import warnings

import numpy as np
import pytest
import yaml

from costmap.grid import GridSpec
from costmap.layers.obstacle import ObstacleParams
from costmap.mapfile import write_map
from costmap.occupancy import OccupancyGrid
from sid.documents import InputWarning
from sid.perception.groups import GroupParams
from sid.scenario.loader import ScenarioError, load_scenario, scenario_from_dict
from sid.scenario.obstacles import BoxObstacle, CircleObstacle, SegmentObstacle
from tests.conftest import REPO_ROOT

EXAMPLE = REPO_ROOT / "examples" / "conversation.json"
BASE = {
    "map": {"resolution": 0.05, "origin": [-1.0, -4.0], "size": [10.0, 8.0]},
    "people": [{"id": 1, "x": 4.0, "y": 0.5, "theta": -1.57}, {"id": 2, "x": 4.0, "y": -0.5, "theta": None}],
    "robot": {"start": [0, 0, 0], "goal": [8, 0, 0]},
}


def with_change(path: str, value) -> dict:
    """BASE with one field replaced; path like 'people.1.theta'."""
    data = copy.deepcopy(BASE)
    node = data
    keys = [int(k) if k.isdigit() else k for k in path.split(".")]
    for key in keys[:-1]:
        node = node[key]
    node[keys[-1]] = value
    return data


def test_example_scenario_loads_with_its_fields():
    s = load_scenario(EXAMPLE)
    assert s.name == "conversation"
    assert (s.grid.width, s.grid.height, s.grid.resolution) == (200, 160, 0.05)
    assert (s.grid.origin_x, s.grid.origin_y) == (-1.0, -4.0)
    assert {type(o) for o in s.obstacles} == {SegmentObstacle, CircleObstacle, BoxObstacle}
    assert [p.id for p in s.people] == [1, 2, 3, 4]
    assert s.robot.start == (0.0, 0.0, 0.0) and s.robot.goal == (8.0, 0.0, 0.0) and s.robot.radius == 0.25
    assert s.lidar.beams == 720 and s.lidar.range_max == 10.0


def test_defaults_apply_when_fields_are_left_out():
    s = scenario_from_dict({"map": {"size": [4, 3]}, "robot": {"start": [1, 1], "goal": [3, 2]}})
    assert s.name == "scenario" and s.grid.resolution == 0.05 and (s.grid.origin_x, s.grid.origin_y) == (0, 0)
    assert s.robot.start == (1.0, 1.0, 0.0) and s.robot.radius == 0.25
    assert s.people == [] and s.obstacles == [] and s.static_map is None
    assert s.group_params == GroupParams() and s.layers.obstacle == ObstacleParams()
    assert s.lidar.body_radius == 0.2


def test_unknown_orientation_and_parameter_blocks():
    data = copy.deepcopy(BASE)
    data["groups"] = {"eps": 1.5, "min_samples": 3}
    data["layers"] = {"inflation": {"inflation_radius": 0.8}, "obstacle": {"track_unknown_space": True}}
    s = scenario_from_dict(data)
    assert s.people[1].theta is None and s.people[1].orientation_quality == 0.0
    assert s.people[0].orientation_quality == 1.0
    assert s.group_params.eps == 1.5 and s.group_params.min_samples == 3
    assert s.layers.inflation.inflation_radius == 0.8 and s.layers.obstacle.track_unknown_space


def test_groups_block_chooses_the_detection_method():
    data = copy.deepcopy(BASE)
    data["groups"] = {"method": "rays", "ray_length": 2.0}
    s = scenario_from_dict(data)
    assert s.group_params.method == "rays" and s.group_params.ray_length == 2.0
    assert scenario_from_dict(copy.deepcopy(BASE)).group_params.method == "ospace"
    for method, message in ((3, "groups.method: expected a string"), ("graphcut", "method must be one of")):
        data["groups"] = {"method": method}
        with pytest.raises(ScenarioError, match=message):
            scenario_from_dict(data)


def test_a_bad_parameter_is_named_once_by_its_block():
    for block, value, message in (
        ("groups", {"method": "nope"}, 'groups: method must be one of ospace, gcff, rays, paper, got "nope"'),
        ("layers", {"social": {"amplitude": 999}}, "layers.social: amplitude must be a finite number in [0, 252]"),
    ):
        data = copy.deepcopy(BASE)
        data[block] = value
        with pytest.raises(ScenarioError) as info:
            scenario_from_dict(data)
        assert str(info.value).startswith(message)


def test_yaml_files_load_too(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(BASE))
    assert load_scenario(path).name == "s"


@pytest.mark.parametrize(
    "path,value,message",
    [
        ("people.1.theta", "north", r"people\[1\]\.theta: expected a finite number"),
        ("people.1.theta", 180, r"people\[1\]: theta 180 is beyond two turns \(4 pi\): radians expected, not degrees"),
        ("robot.goal", [8, 0, 90], r"robot\.goal: yaw 90 is beyond two turns \(4 pi\): radians expected, not degrees"),
        ("people.0.x", math.nan, r"people\[0\]\.x: expected a finite number"),
        ("people.0.x", 42.0, r"people\[0\]: \(42.0, 0.5\) is outside the map"),
        ("people.1.id", 1, r"people\[1\]\.id: 1 is already used by people\[0\]"),
        ("map.resolution", 0, r"map\.resolution: expected a positive number"),
        ("map.size", [10], r"map\.size: expected a list of 2 numbers"),
        ("map.origin", [0, 0, 0.5], r"map\.origin: a rotated map is not supported"),
        ("robot.start", [0, math.inf, 0], r"robot\.start\[1\]: expected a finite number"),
        ("robot.goal", [20, 0, 0], r"robot\.goal: .* outside the map"),
        ("robot.radius", -0.1, r"robot\.radius: expected a positive number"),
        ("obstacles", [{"type": "wall"}], r"obstacles\[0\]\.type"),
        ("obstacles", [{"type": "circle", "center": [1, 1]}], r"obstacles\[0\]\.radius: required"),
        ("obstacles", [{"type": "box", "min": [1, 1], "max": [0, 2]}], r"obstacles\[0\]: min"),
        ("obstacles", [{"type": "segment", "points": [[0, 0]]}], r"obstacles\[0\]\.points: expected at least 2"),
        ("lidar", {"beams": 0}, r"lidar\.beams: expected an integer >= 1"),
        ("groups", {"epsilon": 1}, r"groups\.epsilon: unknown field"),
        ("layers", {"inflation": {"inflation_radius": -1}}, r"layers\.inflation: inflation_radius"),
        ("layers", {"social": {"group_cost": 300}}, r"layers\.social: group_cost"),
        ("layers", {"tracked_people": {"lookahead": -1}}, r"layers\.tracked_people: .*lookahead"),
        ("layers", {"tracked_people": {"lookahead": 1e308}}, r"lookahead must be .* in \[0, 10\]"),
        ("peple", [], r"scenario\.peple: unknown field"),
    ],
)
def test_malformed_fields_are_named(path, value, message):
    with pytest.raises(ScenarioError, match=message):
        scenario_from_dict(with_change(path, value))


def test_missing_map_and_robot_are_named():
    with pytest.raises(ScenarioError, match="map: required"):
        scenario_from_dict({"robot": {"start": [0, 0], "goal": [1, 1]}})
    with pytest.raises(ScenarioError, match="scenario.robot: required"):
        scenario_from_dict({"map": {"size": [2, 2]}})


def test_file_errors_name_the_file(tmp_path):
    with pytest.raises(ScenarioError, match="cannot read scenario file"):
        load_scenario(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(ScenarioError, match="bad.json: not valid JSON"):
        load_scenario(bad)
    nan = tmp_path / "nan.json"
    nan.write_text(json.dumps(with_change("people.0.y", math.nan)))  # JSON's NaN literal
    with pytest.raises(ScenarioError, match=r"nan.json: people\[0\]\.y"):
        load_scenario(nan)


def test_static_map_path_is_relative_to_the_scenario_and_gives_the_geometry(tmp_path):
    spec = GridSpec(0.1, -2.0, -1.0, 30, 20)
    write_map(tmp_path / "maps" / "room.yaml", OccupancyGrid(spec, np.zeros(spec.shape, dtype=np.int8)))
    path = tmp_path / "s.json"
    path.write_text(json.dumps({"static_map": "maps/room.yaml", "robot": {"start": [0, 0], "goal": [0.5, 0.5]}}))
    s = load_scenario(path)
    assert s.static_map == tmp_path / "maps" / "room.yaml" and s.grid == spec


def test_unreadable_static_map_is_named(tmp_path):
    path = tmp_path / "s.json"
    path.write_text(json.dumps({**BASE, "static_map": "nowhere.yaml"}))
    with pytest.raises(ScenarioError, match=r"static_map: .*nowhere.yaml: cannot read map YAML"):
        load_scenario(path)
    (tmp_path / "broken.yaml").write_text(
        "image: broken.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.25\n"
    )
    (tmp_path / "broken.pgm").write_bytes(b"not an image")
    path.write_text(json.dumps({**BASE, "static_map": "broken.yaml"}))
    with pytest.raises(ScenarioError, match="cannot read map image"):
        load_scenario(path)


def test_a_static_map_with_no_cell_in_the_scenarios_map_is_refused(tmp_path):
    """A map file 1 km away (an origin in other coordinates) would leave every cell unknown: its walls gone."""
    spec = GridSpec(0.1, 1000.0, 1000.0, 30, 20)
    write_map(tmp_path / "far.yaml", OccupancyGrid(spec, np.zeros(spec.shape, dtype=np.int8)))
    with pytest.raises(ScenarioError, match=r"far.yaml: the map \(x 1000..1003, y 1000..1002\) lies outside the "):
        scenario_from_dict({**BASE, "static_map": "far.yaml"}, tmp_path)
    touching = GridSpec(0.1, -1.0, 4.0, 30, 20)  # shares the scenario map's upper edge only (y = 4)
    write_map(tmp_path / "touching.yaml", OccupancyGrid(touching, np.zeros(touching.shape, dtype=np.int8)))
    with pytest.raises(ScenarioError, match="no cell in common"):
        scenario_from_dict({**BASE, "static_map": "touching.yaml"}, tmp_path)


@pytest.mark.parametrize("xy", [[9.0, 0.0], [2.0, 4.0], [9.0, 4.0]])
def test_a_person_on_the_maps_upper_or_right_border_is_told_why_it_is_outside(xy):
    with pytest.raises(ScenarioError, match=r"is outside the map \(x -1..9, y -4..4\): the upper and right borders"):
        scenario_from_dict(with_change("people.0", {"id": 1, "x": xy[0], "y": xy[1], "theta": 0.0}))
    with pytest.raises(ScenarioError, match=r"is outside the map \(x -1..9, y -4..4\)$"):
        scenario_from_dict(with_change("people.0", {"id": 1, "x": 9.5, "y": 4.0, "theta": 0.0}))


def test_an_obstacle_outside_the_map_within_the_robots_radius_of_its_edge_is_warned_of():
    """The map spans y -4..4: a wall 2 cm below it holds no cell, so plans pass the edge as if it were not there
    and sid simulate's robot hit it."""
    below = {"type": "segment", "points": [[0.0, -4.02], [5.0, -4.02]]}
    with pytest.warns(InputWarning, match=r"^obstacles\[0\]: lies outside the map \(x -1..9, y -4..4\) but 0.02 m "):
        scenario_from_dict({**BASE, "obstacles": [below]})
    far = {"type": "box", "min": [0.0, -5.0], "max": [5.0, -4.3]}  # 0.3 m below: beyond the robot's 0.25 m
    crossing = {"type": "segment", "points": [[0.0, -4.5], [0.0, -3.0]]}
    on_edge = {"type": "circle", "center": [9.1, 0.0], "radius": 0.1}  # touches x = 9
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scenario_from_dict({**BASE, "obstacles": [far, crossing, on_edge]})


@pytest.mark.parametrize("scene", sorted((REPO_ROOT / "sid" / "experiments" / "simulate" / "scenes").glob("*.yaml")))
def test_a_simulation_scene_is_a_scenario_file_too(scene):
    """sid plan, costmap and compare read sid simulate's scenes: their ``simulation`` block is left to sid simulate."""
    scenario = load_scenario(scene)
    assert scenario.name == scene.stem and scenario.people


def test_a_simulation_block_must_be_a_mapping():
    with pytest.raises(ScenarioError, match=r"^simulation: expected a mapping \(sid simulate's settings"):
        scenario_from_dict({**BASE, "simulation": [1]})
