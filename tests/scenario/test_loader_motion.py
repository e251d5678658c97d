"""Scenario files: people and robot motion fields, declared conversations, and their errors."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import pytest

from sid.scenario.loader import ScenarioError, load_scenario, scenario_from_dict

BASE: dict[str, Any] = {
    "map": {"resolution": 0.1, "origin": [-1.0, -5.0], "size": [10.0, 10.0]},
    "robot": {"start": [0.0, 0.0, 0.0], "goal": [8.0, 0.0]},
    "people": [
        {"id": 1, "x": 3.0, "y": 0.4, "theta": -1.57},
        {"id": 2, "x": 3.0, "y": -0.4, "theta": 1.57},
        {"id": 3, "x": 2.0, "y": 3.0, "path": [[2.0, -3.0], [4.0, -3.0]], "speed": 1.0, "start_time": 2.5},
    ],
    "conversations": [[1, 2]],
}


def _with(**changes: Any) -> dict:
    """BASE with fields set (``people__2__speed=1``: data["people"][2]["speed"] = 1) or removed (None)."""
    data = copy.deepcopy(BASE)
    for key, value in changes.items():
        *path, last = key.split("__")
        node = data
        for part in path:
            node = node[int(part)] if isinstance(node, list) else node[part]
        if value is None:
            node.pop(last)
        else:
            node[last] = value
    return data


def test_walks_robot_path_and_conversations_are_read(tmp_path: Path) -> None:
    data = _with(robot__path=[[4.0, 0.0], [4.0, 2.0]], robot__speed=0.4)
    path = tmp_path / "moving.json"
    path.write_text(json.dumps(data))
    scenario = load_scenario(path)
    assert scenario.conversations == ((1, 2),)
    walk = scenario.walks[3]
    assert walk.path == ((2.0, -3.0), (4.0, -3.0)) and walk.speed == 1.0 and walk.start_time == 2.5
    assert walk.yaw is None and set(scenario.walks) == {3}
    standing = scenario.trajectory(scenario.people[0])
    assert standing.path == () and (standing.x, standing.y, standing.yaw) == (3.0, 0.4, -1.57)
    robot = scenario.robot.trajectory
    assert robot.path == ((4.0, 0.0), (4.0, 2.0)) and robot.speed == 0.4 and robot.end_time == pytest.approx(15.0)
    assert scenario_from_dict(BASE).robot.trajectory.path == ()  # no robot path: it stays at its start
    assert scenario_from_dict(_with(people__2__speed=None)).walks[3].speed == 1.2  # the default walking speed


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"people__2__path": [2.0, -3.0]}, r"people\[2\]\.path\[0\]: expected a list of 2 numbers"),
        ({"people__2__path": "north"}, r"people\[2\]\.path: expected a non-empty list of \[x, y\] waypoints"),
        ({"people__2__path": []}, r"people\[2\]\.path: expected a non-empty list"),
        ({"people__2__path": [[2.0, float("nan")]]}, r"people\[2\]\.path\[0\]\[1\]: expected a finite number"),
        ({"people__2__path": [[2.0, 30.0]]}, r"people\[2\]\.path\[0\]: \(2.0, 30.0\) is outside the map"),
        (
            {"people__2__path": [[2.0, 3.0]]},
            r"people\[2\]\.path\[0\]: \[2.0, 3.0\] repeats the point the path starts from",
        ),
        (
            {"people__2__path": [[2.0, 2.0], [2.0, 2.0]]},
            r"people\[2\]\.path\[1\]: \[2.0, 2.0\] repeats the point before it",
        ),
        ({"people__2__speed": 0}, r"people\[2\]\.speed: expected a positive number, got 0"),
        ({"people__2__speed": float("nan")}, r"people\[2\]\.speed: expected a finite number"),
        ({"people__2__start_time": -1}, r"people\[2\]\.start_time: expected a number >= 0"),
        ({"people__0__speed": 1.0}, r"people\[0\]\.speed: only meaningful with a path"),
        ({"people__0__start_time": 1.0}, r"people\[0\]\.start_time: only meaningful with a path"),
        ({"robot__speed": 1.0}, r"robot\.speed: only meaningful with a path"),
        ({"robot__path": [[4.0, 0.0]], "robot__speed": -1}, r"robot\.speed: expected a positive number"),
        ({"conversations": [[1]]}, r"conversations\[0\]: expected a list of at least two person ids"),
        ({"conversations": [[1, 9]]}, r"conversations\[0\]: person 9 is not in people"),
        ({"conversations": [[1, 2], [2, 3]]}, r"conversations\[1\]: person 2 is already in conversations\[0\]"),
    ],
)
def test_bad_motion_fields_name_the_person_and_field(changes: dict, message: str) -> None:
    with pytest.raises(ScenarioError, match=message):
        scenario_from_dict(_with(**changes))
