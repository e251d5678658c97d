"""``sid plan`` and ``sid demo`` end to end (in process): outputs, exit codes and error messages."""

from __future__ import annotations

import copy
import json

import cv2
import pytest

from costmap.render import OBSTACLE, default_scale, world_to_image
from sid.cli import main
from sid.cli.common import ExitCode
from sid.experiments.demo import DEMO_SCENARIO
from sid.experiments.path_metrics import FIXED_KEYS
from sid.scenario.loader import load_scenario


def write_scenario(tmp_path, **robot) -> str:
    data = copy.deepcopy(DEMO_SCENARIO)
    data["robot"].update(robot)
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(data))
    return str(path)


def test_plan_writes_path_and_picture(tmp_path, capsys):
    out = tmp_path / "out"
    code = main(["plan", write_scenario(tmp_path), "--out", str(out), "--seed", "3", "--iterations", "3000"])
    assert code == 0
    record = json.loads((out / "path.json").read_text())
    assert set(FIXED_KEYS) <= set(record) and record["success"] is True
    assert record["waypoints"][0] == [0.0, 0.0] and record["waypoints"][-1] == [9.0, 0.0]
    assert record["social_layer"] is True and record["ospace_intrusion_m"] == 0.0
    assert (out / "plan.png").stat().st_size > 10_000
    # The picture outlines the declared box (6.8..7.6, -3.0..-1.6) whole: its face x = 7.6, which the scan from the
    # start never hits, is a vertical line 1.4 m (112 px) long.
    img = cv2.imread(str(out / "plan.png"))
    spec = load_scenario(write_scenario(tmp_path)).grid
    u = int(round(world_to_image([[7.6, 0.0]], spec, default_scale(spec))[0, 0]))
    assert 105 <= sum(tuple(pixel) == OBSTACLE for pixel in img[:, u]) <= 130
    printed = capsys.readouterr().out
    assert "repeat exactly: --seed 3 --iterations" in printed and "wrote" in printed


def test_a_plan_stopped_before_its_first_iteration_suggests_no_repeat(tmp_path, capsys):
    # "--iterations 0" used to be suggested, which sid plan itself refuses.
    out = tmp_path / "out"
    code = main(["plan", write_scenario(tmp_path), "--out", str(out), "--planner", "rrtconnect", "--time", "1e-300"])
    printed = capsys.readouterr().out
    assert code == ExitCode.NO_PATH and "found no path" in printed and "repeat exactly" not in printed


def test_plan_without_social_layer_crosses_the_conversation(tmp_path):
    out = tmp_path / "out"
    assert main(["plan", write_scenario(tmp_path), "--out", str(out), "--no-social", "--planner", "grid"]) == 0
    record = json.loads((out / "path.json").read_text())
    assert record["social_layer"] is False and record["crosses_group"] is True


@pytest.mark.parametrize(
    ("robot", "args", "message", "expected"),
    [
        ({"goal": [5.0, -2.9, 0.0]}, [], "no path: goal (5.00, -2.90) is in collision", ExitCode.NO_PATH),
        ({}, ["--planner", "prmstar"], "PRM* is not available", ExitCode.USAGE),
        ({}, ["--planner", "dstar"], "unknown planner 'dstar'", ExitCode.USAGE),
    ],
)
def test_plan_refuses_impossible_or_bad_requests(tmp_path, capsys, robot, args, message, expected):
    code = main(["plan", write_scenario(tmp_path, **robot), "--out", str(tmp_path / "out"), *args])
    assert code == expected
    assert message in capsys.readouterr().err


@pytest.mark.parametrize(
    ("obstacle", "message"),
    [
        (
            {"type": "box", "min": [8.0, -1.0], "max": [9.6, 1.0]},
            "sid plan: no path: goal (9.00, 0.00) is in collision: it lies inside an obstacle (cell cost 254, lethal)",
        ),
        (
            {"type": "segment", "points": [[8.0, -1.0], [9.6, -1.0], [9.6, 1.0], [8.0, 1.0], [8.0, -1.0]]},
            "sid plan: no path: the start and the goal lie in separate free regions of the costmap",
        ),
    ],
)
def test_plan_says_no_path_for_a_goal_inside_a_box_or_walled_in(tmp_path, capsys, obstacle, message):
    """The declared obstacles are the known map, whole: also the faces the scan from the start cannot see."""
    data = copy.deepcopy(DEMO_SCENARIO)
    data["obstacles"].append(obstacle)
    path = tmp_path / "scenario.json"
    path.write_text(json.dumps(data))
    assert main(["plan", str(path), "--out", str(tmp_path / "out"), "--planner", "grid"]) == ExitCode.NO_PATH
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(message)
    assert not (tmp_path / "out" / "path.json").exists()


def test_plan_that_finds_nothing_exits_with_no_path_and_says_so(tmp_path, capsys):
    out = tmp_path / "out"
    args = ["plan", write_scenario(tmp_path), "--out", str(out), "--planner", "rrtstar", "--iterations", "2"]
    assert main([*args, "--seed", "1"]) == ExitCode.NO_PATH
    assert "rrtstar found no path" in capsys.readouterr().out
    record = json.loads((out / "path.json").read_text())
    assert record["success"] is False and record["waypoints"] == [] and record["ospace_intrusion_m"] is None


def test_plan_warns_when_the_goal_is_inside_a_group_zone(tmp_path, capsys):
    scenario = write_scenario(tmp_path, goal=[4.5, 0.0, 0.0])
    assert main(["plan", scenario, "--out", str(tmp_path / "out"), "--planner", "grid"]) == 0
    assert "inside the interaction zone of group (1, 2, 3)" in capsys.readouterr().err


def test_demo_command_prints_the_table(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path / "demo"), "--iterations", "3000"]) == 0
    printed = capsys.readouterr().out
    assert "[1/2]" in printed and "in group zone" in printed and "comparison.png" in printed
    assert set(json.loads((tmp_path / "demo" / "metrics.json").read_text())) == {"without", "with"}


def test_a_path_between_a_groups_members_is_named_on_stderr(tmp_path, capsys):
    """A pair talking across a 2 m corridor leaves no way round: the plan passes between them, and the summary said
    only "crosses a group: yes". A note names the group and why."""
    scenario = {
        "map": {"origin": [0, -0.5], "size": [10, 3]},
        "obstacles": [
            {"type": "segment", "points": [[0, 0], [10, 0]]},
            {"type": "segment", "points": [[0, 2], [10, 2]]},
        ],
        "people": [{"id": 1, "x": 5.0, "y": 0.3, "theta": 1.5708}, {"id": 2, "x": 5.0, "y": 1.7, "theta": -1.5708}],
        "robot": {"start": [0.6, 1.0, 0], "goal": [9.4, 1.0, 0]},
    }
    path = tmp_path / "corridor.json"
    path.write_text(json.dumps(scenario))
    assert main(["plan", str(path), "--planner", "grid", "--out", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err
    assert "sid plan: note: the path passes between members of group (1, 2): no way round was cheaper" in err
    assert main(["plan", str(path), "--planner", "grid", "--no-social", "--out", str(tmp_path / "bare")]) == 0
    assert "passes between members" not in capsys.readouterr().err  # without recognition the robot knows no group
