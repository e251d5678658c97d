"""Closed-loop runs on small worlds (exact perception unless the test is about the camera; a few seconds each)."""

import copy

import numpy as np
import pytest

from costmap.grid import LETHAL, GridSpec
from costmap.mapfile import write_map
from costmap.occupancy import OCC_OCCUPIED, OccupancyGrid
from sid.experiments.simulate import loop
from sid.experiments.simulate.loop import RunOptions, make_sensing, simulate
from sid.experiments.simulate.metrics import run_metrics
from sid.experiments.simulate.world import collision, obstacle_geometry, world_from_dict
from sid.perception.robot_pose import RobotPose
from sid.scenario.build import map_walls
from sid.scenario.lidar import simulate_scan
from tests.experiments.simulate.tiny import TINY, tiny_world

EXACT = RunOptions(perception="exact")


def test_with_the_social_layer_the_robot_goes_around_the_pair_and_without_it_cuts_through():
    world = tiny_world()
    with_ = run_metrics(simulate(world, EXACT), 4.0)
    without = run_metrics(simulate(world, RunOptions(social=False)), 4.0)
    for run in (with_, without):
        assert run["success"] and run["collisions"] == 0
        assert run["trajectory"][0][1:3] == [0.0, 0.0]
    assert with_["ospace_intrusion_m"] == 0.0 and not with_["crosses_group"]
    assert without["ospace_intrusion_m"] > 0.5 and without["crosses_group"]
    assert with_["min_person_distance_m"] > without["min_person_distance_m"]
    assert with_["time_to_goal_s"] <= 10.0


def test_a_start_inside_an_obstacle_ends_at_once_with_the_reason():
    world = tiny_world(obstacles=[*TINY["obstacles"], {"type": "box", "min": [-0.3, -0.3], "max": [0.3, 0.3]}])
    trace = simulate(world, EXACT)
    assert not trace.success and trace.time_s == 0.0
    assert "start" in trace.reason and "in collision" in trace.reason


def test_an_unreachable_goal_ends_at_once_with_the_reason():
    wall = {"type": "segment", "points": [[3.5, -2.0], [3.5, 2.0]]}
    trace = simulate(tiny_world(obstacles=[*TINY["obstacles"], wall]), EXACT)
    assert not trace.success and trace.time_s == 0.0
    assert "separate free regions" in trace.reason


def test_people_blocking_the_corridor_for_good_end_at_the_time_limit():
    people = [{"id": i + 1, "x": 2.0, "y": y, "theta": 3.1416} for i, y in enumerate((-1.35, -0.45, 0.45, 1.35))]
    trace = simulate(tiny_world(people=people, simulation={"time_limit_s": 2.0}), RunOptions(social=False))
    assert not trace.success and trace.collisions == 0
    assert trace.time_s == pytest.approx(2.0)
    # every call failed, each after checking the costmap: their time counts (it was 0.0, as if nothing was planned)
    assert trace.plans == 2 and trace.planning_time_s > 0.0
    assert trace.reason.startswith("time limit (2 s) reached: no path: the start and the goal lie in separate")
    assert trace.reason.endswith(
        "people 1 at (2.00, -1.35), 2 at (2.00, -0.45), 3 at (2.00, 0.45), 4 at (2.00, 1.35) close the way between "
        "them (without people it is open): a person is an obstacle of radius 0.20 m (lidar.body_radius) and the robot "
        "a disc of radius 0.25 m (robot.radius)"
    )


def test_a_person_standing_on_the_goal_is_named_at_the_time_limit():
    # the goal lay inside person 1's body: the reason read only "it lies inside an obstacle", as if a wall stood there
    people = [{"id": 1, "x": 4.0, "y": 0.0, "theta": 3.1416}]
    trace = simulate(tiny_world(people=people, simulation={"time_limit_s": 1.0}), EXACT)
    assert not trace.success and trace.collisions == 0
    assert trace.reason.startswith("time limit (1 s) reached: no path: goal (4.00, 0.00) is in collision")
    assert trace.reason.endswith(
        "the goal is 0.00 m from person 1 at (4.00, 0.00): a person is an obstacle of radius 0.20 m "
        "(lidar.body_radius) and the robot a disc of radius 0.25 m (robot.radius)"
    )


def test_the_unknown_map_is_discovered_by_the_lidar():
    box = {"type": "box", "min": [1.5, -0.5], "max": [2.5, 0.5]}
    world = tiny_world(obstacles=[*TINY["obstacles"], box], people=[])
    run = run_metrics(simulate(world, RunOptions(social=False, unknown_map=True)), 4.0)
    assert run["success"] and run["collisions"] == 0


def test_camera_runs_repeat_exactly():
    world = tiny_world(simulation={"time_limit_s": 1.5})
    first, again = (simulate(world, RunOptions(seed=3)) for _ in range(2))
    assert first.trajectory == again.trajectory and first.reason == again.reason
    assert len(first.trajectory) == 16 and first.plans == again.plans


def test_a_walker_that_runs_into_the_robot_is_a_collision():
    data = copy.deepcopy(TINY)
    data["people"] = [{"id": 1, "x": 3.0, "y": 0.0, "theta": 3.1416, "path": [[-0.4, 0.0]], "speed": 1.5}]
    data["simulation"] = {"max_speed": 0.1, "time_limit_s": 5.0}
    trace = simulate(world_from_dict(data), RunOptions(social=False))
    assert not trace.success and trace.collisions == 1
    assert trace.reason.startswith("collision with person 1")


def _headon_corridor() -> dict:
    """An 8 m corridor 2.4 m wide; a walker comes down its middle at 1.2 m/s, head-on, towards a robot of 0.5 m/s."""
    data = copy.deepcopy(TINY)
    data["map"] = {"resolution": 0.05, "origin": [-0.5, -1.5], "size": [9.0, 3.0]}
    data["obstacles"] = [{"type": "segment", "points": [[-0.5, y], [8.5, y]]} for y in (1.2, -1.2)]
    data["people"] = [{"id": 1, "x": 8.3, "y": 0.0, "path": [[-0.4, 0.0]], "speed": 1.2}]
    data["robot"]["goal"] = [7.5, 0.0, 0.0]
    data["simulation"] = {"max_speed": 0.5, "time_limit_s": 30.0}
    return data


def test_exact_perception_knows_a_walkers_velocity_and_steps_aside():
    # exact perception painted the walker as if standing (no velocity): the robot kept to the middle until the
    # walker's body blocked its path and they collided at t = 5.3 s (the camera's tracks know the velocity)
    trace = simulate(world_from_dict(_headon_corridor()), EXACT)
    assert trace.success and trace.collisions == 0


def test_exact_perception_groups_standing_people_only():
    data = _headon_corridor()  # a pair talks across the corridor; beyond, two walkers come side by side
    data["people"] = [
        *({"id": i, "x": 4.0, "y": y, "path": [[-0.4, y]], "speed": 1.0} for i, y in ((1, 0.3), (2, -0.3))),
        *({"id": i, "x": 2.0, "y": y, "theta": -1.5708 * y / abs(y)} for i, y in ((3, 0.9), (4, -0.9))),
    ]
    world = world_from_dict(data)
    sensing = make_sensing(world, EXACT)
    scan = simulate_scan((0.0, 0.0, 0.0), world.scenario.obstacles, world.people_at(0.0), beams=720, range_max=10.0)
    seen = sensing(0, RobotPose(0.0, 0.0, 0.0), world.people_at(0.0), scan)
    assert [p.id for p in seen.people] == [1, 2, 3, 4]
    assert [g.members for g in seen.groups] == [(3, 4)]  # the walkers were a conversation too


def test_a_walker_that_walks_into_a_waiting_robot_is_a_collision_that_says_so():
    # The goal lies on the walker's way, so the robot waits for it to clear; scripted walkers do not avoid the robot.
    data = copy.deepcopy(TINY)
    data["people"] = [{"id": 1, "x": 4.4, "y": 0.0, "theta": 3.1416, "path": [[-0.4, 0.0]], "speed": 1.0,
                       "start_time": 0.5}]  # fmt: skip
    data["robot"]["goal"] = [4.0, 0.0, 0.0]
    trace = simulate(world_from_dict(data), RunOptions(social=False))
    assert trace.collisions == 1
    assert trace.reason.startswith("collision with person 1") and trace.reason.endswith(
        "(the robot was standing still: the person walked into it)"
    )


@pytest.mark.parametrize(
    ("changes", "hit"),
    [
        ({"obstacles": [{"type": "box", "min": [-0.3, -0.3], "max": [0.3, 0.3]}]}, "obstacle"),
        ({"people": [{"id": 7, "x": 0.2, "y": 0.0, "theta": 0.0}]}, "person 7"),
    ],
)
def test_a_run_that_starts_in_collision_says_so_not_that_a_person_walked_in(changes, hit):
    """Without the known map (or a person, whom the known map leaves out) nothing refuses such a start before the
    run: its first step ends it, and the reason says where, not "the person walked into it"."""
    trace = simulate(tiny_world(**changes), RunOptions(social=False, unknown_map=True))
    assert trace.reason == f"collision with {hit} at t = 0.0 s (where the robot starts: its disc overlaps it)"


def test_an_onnx_pose_model_runs_in_the_loop(tmp_path):
    pytest.importorskip("onnx")
    import numpy as np

    from tests.pose_models import build_yolo_pose_model, yolo_candidate

    keypoints = np.column_stack([np.full(17, 128.0), np.linspace(60.0, 200.0, 17)])
    model = build_yolo_pose_model(tmp_path / "pose.onnx", yolo_candidate([128, 128, 60, 160], 0.9, keypoints)[:, None])
    trace = simulate(tiny_world(simulation={"time_limit_s": 0.3}), RunOptions(model=model))
    assert trace.reason == "time limit (0.3 s) reached" and len(trace.trajectory) == 4


def _file_wall_world(tmp_path, **simulation):
    """The tiny corridor, nobody in it, and a wall 0.2 m thick across it at x = 2 with a gap at the top, drawn only
    in a static_map file."""
    spec = GridSpec.from_size(0.05, (-0.5, -2.0), (5.0, 4.0))
    xs, ys = spec.cell_centres()
    data = np.zeros(spec.shape, dtype=np.int8)
    data[(xs > 1.9) & (xs < 2.1) & (ys < 0.6)] = OCC_OCCUPIED
    write_map(tmp_path / "wall.yaml", OccupancyGrid(spec, data))
    data = copy.deepcopy(TINY) | {"people": [], "static_map": "wall.yaml"}
    data["simulation"] |= simulation
    return world_from_dict(data, base_dir=tmp_path)


@pytest.mark.parametrize("unknown_map", [False, True])
def test_a_static_map_files_walls_are_seen_by_the_lidar_and_unknown_with_unknown_map(tmp_path, unknown_map):
    steps = []
    trace = simulate(_file_wall_world(tmp_path), RunOptions(social=False, unknown_map=unknown_map), steps.append)
    assert trace.success and trace.collisions == 0
    first = steps[0]
    ahead = first.scan.ranges[np.argmin(np.abs(first.scan.angles))]  # beam along +x from (0, 0)
    assert ahead == pytest.approx(1.9, abs=0.06)  # the wall's near face, drawn only in the file
    behind_face = first.costmap.costs[first.costmap.spec.world_to_cell(np.array([2.05, 0.0]))[0].tolist()]
    assert (behind_face == LETHAL) is not unknown_map  # with unknown_map only the LiDAR's marks: the face


def test_a_static_map_files_walls_are_obstacles_the_robot_collides_with(tmp_path):
    world = _file_wall_world(tmp_path)
    geometry = obstacle_geometry(world.scenario.obstacles, map_walls(world.scenario))
    assert collision((2.0, -1.0), 0.25, geometry, [], 0.2) == "obstacle"
    assert collision((2.0, 1.2), 0.25, geometry, [], 0.2) is None  # in the gap


def test_a_start_grazing_an_inflated_wall_escapes_in_a_second_planner_call_that_is_counted():
    world = tiny_world(people=[])
    planner = loop._Planner(world, RunOptions(social=False))
    costmap = make_sensing(world, RunOptions(social=False), walls=map_walls(world.scenario)).costmap.master
    start = (0.0, 1.6)  # 0.2 m from the wall at y = 1.8, inside the 0.25 m robot's inflation: the first call refuses
    result = planner._plan(costmap, start)
    assert result is not None and result.success
    assert tuple(result.path[0]) == start and tuple(result.path[1]) != start  # the path leads out from the escape
    assert planner.plans == 2 and "no path: start" in planner.message


def _ambush(start_time: float) -> dict:
    """At 1 Hz: a walker comes out from behind a box at 1.5 m/s across the robot's straight way (0.5 m/s along y = 0),
    and at whole seconds stands 0.75 m to one side of it and then the other."""
    return {
        "name": "ambush",
        "map": {"resolution": 0.05, "origin": [-1.0, -4.0], "size": [12.0, 8.0]},
        "obstacles": [{"type": "box", "min": [2.5, -4.0], "max": [3.5, -0.8]}],
        "people": [{"id": 1, "x": 4.0, "y": -3.0, "theta": 1.5708, "path": [[4.0, 3.5]], "speed": 1.5,
                    "start_time": start_time}],
        "robot": {"start": [0.0, 0.0, 0.0], "goal": [10.0, 0.0, 0.0], "radius": 0.25},
        "simulation": {"rate_hz": 1.0, "time_limit_s": 40.0},
    }  # fmt: skip


def test_a_walker_crossing_the_robot_between_two_steps_is_a_collision():
    # Checked at the steps alone, the walker stood 0.75 m from the robot at t = 7 s and t = 8 s, and the run reached
    # its goal; in between they were 0.30 m apart, under the 0.45 m of the two bodies (0.24 m before the follower ran
    # at its own rate between the 1 s steps, MAX_CONTROL_PERIOD_S).
    trace = simulate(world_from_dict(_ambush(5.5)), EXACT)
    assert not trace.success and trace.collisions == 1 and trace.reason.startswith("collision with person 1 at t = 8")
    assert run_metrics(trace, 10.0)["min_person_distance_m"] == pytest.approx(0.296, abs=0.001)


def test_the_closest_approach_is_over_the_step_not_against_where_the_people_were_at_its_start():
    # Half a second earlier the walker passes in front of the robot: 0.561 m at the closest (a walker moving straight
    # between the steps' positions; 0.495 m before the follower ran at its own rate between the 0.5 s steps); the
    # segment against the walker's position at each step's start read 0.388 m then.
    world = world_from_dict(_ambush(5.0) | {"simulation": {"rate_hz": 2.0, "time_limit_s": 40.0}})
    trace = simulate(world, EXACT)
    assert trace.success and trace.collisions == 0
    assert run_metrics(trace, 10.0)["min_person_distance_m"] == pytest.approx(0.5606, abs=0.001)


def test_a_world_stepped_at_half_a_hertz_still_follows_a_bend_round_a_pair():
    """Held for a whole 2 s step, the follower's turn in place passed the bend's bearing and back until the time
    limit (a probe, 7 December 2026); it now runs at least every MAX_CONTROL_PERIOD_S between the world's steps."""
    corridor = [{"type": "segment", "points": [[0, y], [10, y]]} for y in (0.5, 3.5)]
    pair = [{"id": 1, "x": 5, "y": 2.9, "theta": -1.57}, {"id": 2, "x": 5, "y": 2.1, "theta": 1.57}]
    world = world_from_dict(
        {
            "map": {"resolution": 0.05, "origin": [0, 0], "size": [10, 4]},
            "obstacles": corridor,
            "people": pair,
            "robot": {"start": [1, 2, 0], "goal": [9, 2, 0]},
            "simulation": {"time_limit_s": 40, "rate_hz": 0.5},
        }
    )
    run = run_metrics(simulate(world, EXACT), 4.0)
    assert run["success"] and run["collisions"] == 0 and run["ospace_intrusion_m"] == 0.0
