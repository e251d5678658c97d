"""``sid.scenario.params_file``: the group detector's and the trackers' parameters from a file."""

from __future__ import annotations

from pathlib import Path

import pytest

from sid.perception.groups import GroupParams
from sid.scenario.loader import ScenarioError
from sid.scenario.params_file import ParamsFile, load_params_file, params_file_from_dict
from sid.tracking.groups import GroupTrackerParams
from sid.tracking.session import TrackingParams
from sid.tracking.tracker import TrackerParams


def test_each_block_sets_its_records_fields_and_leaves_the_others_at_their_defaults() -> None:
    params = params_file_from_dict(
        {
            "groups": {"positions_only_reach": 1.0, "method": "ospace", "radius_steps": 5},
            "tracking": {"tracker": {"timeout": 2, "confirm_hits": 1}, "groups": {"walk_distance": 1.2},
                         "max_robot_speed": 1.0},
        }
    )  # fmt: skip
    assert params.groups == GroupParams(positions_only_reach=1.0, radius_steps=5)
    assert params.tracking == TrackingParams(
        tracker=TrackerParams(timeout=2.0, confirm_hits=1), groups=GroupTrackerParams(walk_distance=1.2),
        max_robot_speed=1.0,
    )  # fmt: skip
    assert isinstance(params.tracking.tracker.timeout, float)  # a YAML 2 for seconds is read as 2.0


def test_infinity_is_taken_where_the_record_takes_it_and_refused_by_the_record_elsewhere(tmp_path: Path) -> None:
    """``--meeting-radius inf`` and ``GroupParams(meeting_radius=math.inf)`` switch the merging off; the file's
    ``.inf`` was refused as not finite."""
    path = tmp_path / "params.yaml"
    path.write_text("groups:\n  method: rays\n  meeting_radius: .inf\n")
    assert load_params_file(path).groups == GroupParams(method="rays", meeting_radius=float("inf"))
    with pytest.raises(
        ScenarioError, match=r"tracking.tracker: timeout must be a finite number of seconds >= 0, got inf"
    ):
        params_file_from_dict({"tracking": {"tracker": {"timeout": float("inf")}}})
    with pytest.raises(ScenarioError, match=r"groups.eps: expected a finite number, got NaN"):
        params_file_from_dict({"groups": {"eps": float("nan")}})


@pytest.mark.parametrize("document", [None, {}, {"groups": {}, "tracking": {}}, {"tracking": {"tracker": {}}}])
def test_an_empty_file_or_empty_blocks_give_the_defaults(document: object) -> None:
    assert params_file_from_dict(document) == ParamsFile()


@pytest.mark.parametrize(
    ("document", "message"),
    [
        ([1, 2], "expected a mapping of the blocks groups and tracking, got [1, 2]"),
        ({"group": {}}, "group: unknown block; the blocks: groups, tracking"),
        ({1: {}}, "1: unknown block; the blocks: groups, tracking"),
        ({"groups": {"alone": 1}}, "groups.alone: unknown field; known fields: "),
        ({"groups": {"method": "dbscan"}}, "groups: method must be one of ospace, gcff, rays, paper"),
        ({"groups": {"radius_steps": 2.5}}, "groups.radius_steps: expected an integer >= 0, got 2.5"),
        ({"tracking": {"people": {}}}, "tracking.people: unknown field; known fields: groups, jump_tolerance, "),
        ({"tracking": {"tracker": 3}}, "tracking.tracker: expected a mapping, got 3"),
        ({"tracking": {"tracker": {"timeout": "2 s"}}}, "tracking.tracker.timeout: expected a finite number, got "),
        ({"tracking": {"tracker": {"timeout": -1}}}, "tracking.tracker: timeout must be a finite number of seconds"),
        ({"tracking": {"groups": {"walk_window": 90}}}, "tracking.groups: walk_window must be a finite number of"),
        ({"tracking": {"max_turn_rate": -1}}, "tracking: max_turn_rate must be a finite number >= 0, got -1.0"),
    ],
)
def test_a_bad_block_or_field_is_refused_naming_it(document: object, message: str) -> None:
    with pytest.raises(ScenarioError) as error:
        params_file_from_dict(document)
    assert str(error.value).startswith(message)


def test_a_file_is_read_as_yaml_or_json_and_its_errors_name_it(tmp_path: Path) -> None:
    yaml_file = tmp_path / "robot.yaml"
    yaml_file.write_text("groups:\n  positions_only_reach: 1.0\ntracking:\n  tracker:\n    measurement_sigma: 0.1\n")
    params = load_params_file(yaml_file)
    assert params.groups.positions_only_reach == 1.0 and params.tracking.tracker.measurement_sigma == 0.1
    json_file = tmp_path / "robot.json"
    json_file.write_text('{"tracking": {"tracker": {"min_gate": 2.0}}}')  # above max_gate (1.0)
    with pytest.raises(ScenarioError, match=rf"^{json_file}: tracking.tracker: max_gate must be"):
        load_params_file(json_file)
    with pytest.raises(ValueError, match=r"missing.yaml: cannot read parameters file"):
        load_params_file(tmp_path / "missing.yaml")
    (tmp_path / "empty.yaml").write_text("")
    assert load_params_file(tmp_path / "empty.yaml") == ParamsFile()
