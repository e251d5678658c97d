"""Conversations the known map allows: nobody is grouped through a wall."""

from __future__ import annotations

from costmap.layers.social import GROUPS
from sid.perception.groups import detect_groups
from sid.scenario.build import build_costmap
from sid.scenario.loader import scenario_from_dict
from sid.scenario.sight import Walls, scenario_groups, scenario_walls

WALL = {"type": "segment", "points": [[0.0, 3.0], [10.0, 3.0]]}  # across the whole room


def _scenario(people: list[dict], obstacles: list[dict]):
    return scenario_from_dict(
        {
            "map": {"resolution": 0.05, "origin": [0.0, 0.0], "size": [10.0, 6.0]},
            "obstacles": obstacles,
            "people": people,
            "robot": {"start": [1.0, 1.0, 0.0], "goal": [9.0, 1.0, 0.0]},
        }
    )


# Person 1 below the wall faces up at person 2 above it, 0.95 m apart; 3 stands beside 2 and faces them.
ACROSS = [
    {"id": 1, "x": 4.5, "y": 2.55, "theta": 1.5708},
    {"id": 2, "x": 4.5, "y": 3.5, "theta": -1.5708},
    {"id": 3, "x": 5.3, "y": 3.5, "theta": 3.1416},
]


def test_people_on_either_side_of_a_wall_are_not_one_group() -> None:
    """Blind to the map, the detector makes one group of the three across the wall (a probe's across_wall scene);
    with it, the two on one side stay a pair and the one below is alone, also in the costmap's social layer."""
    scenario = _scenario(ACROSS, [WALL])
    assert [g.members for g in detect_groups(scenario.people, scenario.group_params)] == [(1, 2, 3)]
    assert [g.members for g in scenario_groups(scenario)] == [(2, 3)]
    assert [g.members for g in build_costmap(scenario).inputs[GROUPS]] == [(2, 3)]


def test_without_a_wall_between_them_the_groups_are_the_detectors() -> None:
    for obstacles in ([], [{"type": "box", "min": [8.0, 0.5], "max": [9.0, 1.0]}]):
        scenario = _scenario(ACROSS, obstacles)
        blind = [g.members for g in detect_groups(scenario.people, scenario.group_params)]
        assert [g.members for g in scenario_groups(scenario)] == blind == [(1, 2, 3)]
    assert scenario_walls(_scenario(ACROSS, [])) is None


def test_a_line_of_sight_is_blocked_by_any_occupied_cell_it_passes() -> None:
    walls = scenario_walls(_scenario([], [WALL]))
    assert isinstance(walls, Walls) and walls.occupied.any()
    assert walls.block((4.5, 2.5), (4.5, 3.5))  # through the wall
    assert walls.block((1.0, 1.0), (9.0, 5.0))  # diagonally through it
    assert not walls.block((1.0, 1.0), (9.0, 2.5))  # below it all the way
    assert not walls.block((2.0, 4.0), (2.0, 4.0))  # a point in free space
    assert not walls.block((-5.0, 1.0), (1.0, 1.0))  # partly off the map: only its cells on the map count
