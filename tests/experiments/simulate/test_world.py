import copy
import re
import warnings

import numpy as np
import pytest

from costmap.grid import GridSpec
from costmap.mapfile import write_map
from costmap.occupancy import OCC_OCCUPIED, OccupancyGrid
from sid.documents import InputWarning
from sid.experiments.simulate.world import closest_approach, collision, obstacle_geometry, world_from_dict
from sid.perception.people import Person
from sid.scenario.loader import BoxObstacle, ScenarioError, SegmentObstacle
from tests.experiments.simulate.tiny import PAIR, TINY, tiny_world


def test_the_simulation_block_sets_the_limits_and_the_robot_radius_comes_from_the_scenario():
    world = tiny_world(simulation={"max_turn_rate": 2.0, "rate_hz": 5.0, "description": "d"})
    limits = world.settings.limits
    assert (limits.max_speed, limits.max_turn_rate, limits.radius) == (1.0, 2.0, 0.25)
    assert world.settings.rate_hz == 5.0 and world.settings.description == "d"
    assert world.settings.time_limit_s == 10.0


@pytest.mark.parametrize(
    ("simulation", "message"),
    [
        ({"max_sped": 1.0}, "simulation.max_sped: unknown field"),
        ({"time_limit_s": 0}, "simulation.time_limit_s: expected a positive number"),
        ({"description": 3}, "simulation.description: expected a string"),
        ({"rate_hz": 1e-300}, r"simulation.rate_hz: expected a number of Hz in \[0.1, 1000\], got 1e-300"),
        ({"rate_hz": 1e5, "time_limit_s": 0.01}, r"simulation.rate_hz: expected a number of Hz in \[0.1, 1000\]"),
    ],
)
def test_a_bad_simulation_block_is_named(simulation, message):
    with pytest.raises(ScenarioError, match=message):
        tiny_world(simulation=simulation)


def test_a_simulation_block_that_is_no_mapping_is_named_as_every_command_names_it():
    with pytest.raises(ScenarioError, match=r"^simulation: expected a mapping \(sid simulate's settings, docs/simu"):
        world_from_dict({**TINY, "simulation": [1.0]})


def test_a_standing_person_without_a_facing_is_refused_by_name_whatever_the_run():
    # The world is ground truth: a person stands facing somewhere; "unknown facing" is what perception reports. The
    # camera cannot render a body without one, so the file is refused on loading, before any run of a sweep.
    people = [PAIR[0], {"id": 2, "x": 2.0, "y": -0.6}]
    with pytest.raises(ScenarioError, match=r"people\[1\]\.theta: .*standing person needs a facing"):
        tiny_world(people=people)
    walker = {"id": 2, "x": 2.0, "y": -0.6, "path": [[2.0, 1.0]]}  # faces the way it walks
    assert tiny_world(people=[PAIR[0], walker]).scenario.people[1].theta is None


BOX = {"type": "box", "min": [2.5, -1.0], "max": [3.0, -0.5]}


@pytest.mark.parametrize(
    ("obstacles", "people", "message"),
    [  # each was run: the robot saw, planned round and could collide with bodies no one could have
        ([BOX], [*PAIR, {"id": 3, "x": 2.7, "y": -0.7, "theta": 0.0}],
         "people[2]: person 3 stands at (2.70, -0.70) on or inside obstacles[2]"),
        ([BOX], [*PAIR, {"id": 3, "x": 2.75, "y": -1.6, "path": [[2.75, 1.0]]}],
         "people[2]: person 3 walks along its path on or inside obstacles[2]"),
        ([], [*PAIR, {"id": 3, "x": 2.0, "y": 0.45, "theta": 0.0}],
         "people[2]: person 3 at (2.00, 0.45) is 0.15 m from person 1 (people[0]) at time 0: inside their body"),
    ],
)  # fmt: skip
def test_a_person_inside_an_obstacle_or_another_body_is_refused_by_name(obstacles, people, message):
    with pytest.raises(ScenarioError, match=re.escape(message)):
        tiny_world(obstacles=[*TINY["obstacles"], *obstacles], people=people)


def test_a_body_inside_a_static_map_files_wall_is_refused(tmp_path):
    spec = GridSpec.from_size(0.05, (-0.5, -2.0), (5.0, 4.0))
    xs, _ = spec.cell_centres()
    write_map(
        tmp_path / "wall.yaml", OccupancyGrid(spec, np.where((xs > 1.9) & (xs < 2.1), OCC_OCCUPIED, 0).astype(np.int8))
    )
    data = copy.deepcopy(TINY) | {"people": [{"id": 1, "x": 2.0, "y": 0.0, "theta": 0.0}], "static_map": "wall.yaml"}
    with pytest.raises(ScenarioError, match=re.escape("person 1 stands at (2.00, 0.00) on or inside the static_map")):
        world_from_dict(data, base_dir=tmp_path)


def test_a_body_drawn_against_a_wall_or_touching_another_is_accepted():
    wall_y = TINY["obstacles"][0]["points"][0][1]  # 1.8
    people = [{"id": i + 1, "x": x, "y": wall_y - 0.2, "theta": 0.0} for i, x in enumerate((2.0, 2.4))]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(tiny_world(people=people).scenario.people) == 2


def test_a_body_only_overlapping_a_wall_or_another_body_is_warned_of_and_run():
    # The body is a disc of lidar.body_radius: real people stand closer than two of them (a pair face to face 0.3 m
    # apart, someone leaning on a wall), so an overlap alone is a warning, not a refusal.
    wall_y = TINY["obstacles"][0]["points"][0][1]  # 1.8
    people = [
        {"id": 1, "x": 2.0, "y": wall_y - 0.1, "theta": 0.0},
        {"id": 2, "x": 2.3, "y": wall_y - 0.3, "theta": 0.0},
    ]
    with pytest.warns(InputWarning) as caught:
        assert len(tiny_world(people=people).scenario.people) == 2
    messages = [str(w.message) for w in caught]
    assert any(m.startswith("people[0]: person 1 stands at (2.00, 1.70) 0.10 m from obstacles[0]") for m in messages)
    assert any(
        "person 2 at (2.30, 1.50) is 0.36 m from person 1 (people[0]) at time 0: two bodies" in m for m in messages
    )


def test_walkers_move_along_their_path_and_face_the_way_they_go():
    data = copy.deepcopy(TINY)
    data["people"] = [{"id": 7, "x": 1.0, "y": -1.0, "theta": 0.0, "path": [[1.0, 1.0]], "speed": 1.0,
                       "start_time": 1.0}]  # fmt: skip
    world = world_from_dict(data)
    before, during, after = (world.people_at(t)[0] for t in (0.5, 2.0, 5.0))
    assert (before.x, before.y, before.theta) == (1.0, -1.0, 0.0)
    assert (during.x, during.y) == pytest.approx((1.0, 0.0))
    assert during.theta == pytest.approx(1.5708, abs=1e-4)
    assert (after.x, after.y) == pytest.approx((1.0, 1.0))


def test_collision_with_obstacles_and_people():
    walls = obstacle_geometry([SegmentObstacle(((0.0, 1.0), (5.0, 1.0))), BoxObstacle((3.0, -2.0), (4.0, -1.0))])
    people = [Person(3, 2.0, 0.0, 0.0)]
    assert collision((0.5, 0.8), 0.25, walls, people, 0.2) == "obstacle"
    assert collision((3.5, -0.8), 0.25, walls, people, 0.2) == "obstacle"
    assert collision((1.6, 0.0), 0.25, walls, people, 0.2) == "person 3"
    assert collision((1.5, 0.0), 0.25, walls, people, 0.2) is None
    assert collision((0.0, 0.0), 0.25, None, [], 0.2) is None


def test_the_closest_approach_of_two_straight_motions_is_the_least_distance_between_them():
    # Robot from (0, 0) to (1, 0); person 1 from (0.5, -1) to (0.5, 1): they meet at (0.5, 0) half-way through.
    # Person 2 walks alongside, 0.3 m to the left; person 3 was not there a step before (taken as standing).
    earlier = [Person(1, 0.5, -1.0, None), Person(2, 0.0, 0.3, None)]
    people = [Person(1, 0.5, 1.0, None), Person(2, 1.0, 0.3, None), Person(3, 2.0, 0.0, None)]
    gaps = closest_approach((0.0, 0.0), (1.0, 0.0), earlier, people)
    assert gaps == pytest.approx([0.0, 0.3, 1.0])
    rng = np.random.default_rng(0)
    for _ in range(200):  # against sampling the step finely
        a0, a1, b0, b1 = rng.uniform(-2, 2, (4, 2))
        exact = closest_approach(tuple(a0), tuple(a1), [Person(1, *b0, None)], [Person(1, *b1, None)])[0]
        s = np.linspace(0, 1, 20001)[:, None]
        sampled = np.hypot(*((b0 + s * (b1 - b0)) - (a0 + s * (a1 - a0))).T).min()
        assert exact == pytest.approx(sampled, abs=1e-6) and exact <= sampled + 1e-12
