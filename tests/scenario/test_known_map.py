"""The known map: a scenario's declared obstacles, whole, in the static layer (also where the start's scan cannot see
them), combined with a ``static_map`` file; and impossible tasks refused with "no path"."""

from __future__ import annotations

import numpy as np
import pytest

from costmap.grid import FREE_SPACE, LETHAL, NO_INFORMATION, GridSpec
from costmap.layers.obstacle import SCAN
from costmap.layers.social import PEOPLE
from costmap.mapfile import write_map
from costmap.occupancy import OCC_OCCUPIED, OCC_UNKNOWN, OccupancyGrid
from planner.facade import plan
from planner.problem import PlanningError
from sid.documents import InputWarning
from sid.scenario.build import build_costmap, planning_problem
from sid.scenario.known_map import known_map, obstacle_mask
from sid.scenario.loader import scenario_from_dict
from sid.scenario.obstacles import BoxObstacle, CircleObstacle, SegmentObstacle, outline

SPEC = GridSpec.from_size(0.05, (0.0, 0.0), (10.0, 6.0))
BOX = {"type": "box", "min": [5.0, 2.0], "max": [6.0, 4.0]}


def scenario(obstacles: list, goal=(9.0, 3.0), base_dir=None, **extra):
    return scenario_from_dict(
        {
            "map": {"resolution": 0.05, "origin": [0.0, 0.0], "size": [10.0, 6.0]},
            "obstacles": obstacles,
            "robot": {"start": [2.0, 3.0, 0.0], "goal": list(goal)},
            **extra,
        },
        base_dir=base_dir,
    )


def cells_of(xy) -> tuple[int, int]:
    row, col = SPEC.world_to_cell(np.array(xy, dtype=float))[0]
    return int(row), int(col)


def test_a_box_is_lethal_whole_although_the_scan_sees_only_its_near_face():
    layered = build_costmap(scenario([BOX]), social=False)
    hits = layered.inputs[SCAN].hit_points()
    on_box = hits[(hits[:, 0] > 4.9) & (hits[:, 0] < 6.1) & (hits[:, 1] > 1.9) & (hits[:, 1] < 4.1)]
    assert len(on_box) > 10 and on_box[:, 0].max() < 5.05  # the scan hits only the face x = 5 it sees
    far_face = [cells_of((6.0, y)) for y in np.arange(2.05, 4.0, 0.1)]
    inside = cells_of((5.5, 3.0))
    lidar, master = layered.grids["lidar"], layered.master.costs
    assert all(lidar[c] != LETHAL for c in [*far_face, inside])  # the LiDAR layer alone has an L at most
    assert all(master[c] == LETHAL for c in [*far_face, inside])
    assert list(layered.grids) == ["static", "lidar", "inflation"]


def test_the_rasterised_shapes_cover_the_cells_they_reach():
    mask = obstacle_mask(
        [
            BoxObstacle((5.0, 2.0), (6.0, 4.0)),
            CircleObstacle((2.0, 1.0), 0.3),
            SegmentObstacle(((1.0, 5.0), (3.0, 5.5), (3.0, 4.5))),
        ],
        SPEC,
    )
    (r0, c0), (r1, c1) = cells_of((5.0, 2.0)), cells_of((6.0, 4.0))
    assert mask[r0 : r1 + 1, c0 : c1 + 1].all() and mask[r0 : r1 + 1, c0 : c1 + 1].sum() == 21 * 41
    assert not mask[r0 - 1, c0] and not mask[r0, c0 - 1] and not mask[r1 + 1, c1] and not mask[r1, c1 + 1]
    xs, ys = SPEC.cell_centres()
    disc = mask & (np.hypot(xs - 2.0, ys - 1.0) < 1.0)
    assert disc[np.hypot(xs - 2.0, ys - 1.0) <= 0.3].all()  # every cell centre inside the circle
    assert not disc[np.hypot(xs - 2.0, ys - 1.0) > 0.3 + 0.05 * np.sqrt(2) / 2].any()  # no cell clear of it
    for t in np.linspace(0, 1, 50):  # every point of the wall's two pieces lies in a marked cell
        assert mask[cells_of((1.0 + 2.0 * t, 5.0 + 0.5 * t))] and mask[cells_of((3.0, 5.5 - t))]
    assert mask.sum() < 21 * 41 + 150 + 2 * (42 + 20) + 20  # and not much more: box, disc, two thin wall pieces


def test_the_outlines_are_the_declared_shapes():
    points, closed = outline(BoxObstacle((5.0, 2.0), (6.0, 4.0)))
    assert closed and points.tolist() == [[5.0, 2.0], [6.0, 2.0], [6.0, 4.0], [5.0, 4.0]]
    points, closed = outline(CircleObstacle((2.0, 1.0), 0.3))
    assert closed and np.allclose(np.hypot(points[:, 0] - 2.0, points[:, 1] - 1.0), 0.3)
    points, closed = outline(SegmentObstacle(((1.0, 5.0), (3.0, 5.5))))
    assert not closed and points.tolist() == [[1.0, 5.0], [3.0, 5.5]]


def test_a_map_file_and_the_obstacles_combine(tmp_path):
    coarse = GridSpec(0.1, 0.0, 0.0, 50, 60)  # a 0.1 m map covering x 0..5 m of the 0.05 m scenario grid
    data = np.zeros(coarse.shape, dtype=np.int8)
    data[:, 10] = OCC_OCCUPIED  # a wall along x = 1.0..1.1 m
    data[50:, 40:] = OCC_UNKNOWN
    write_map(tmp_path / "room.yaml", OccupancyGrid(coarse, data))
    grid = known_map([BoxObstacle((5.0, 2.0), (6.0, 4.0))], SPEC, OccupancyGrid(coarse, data))
    assert grid.spec == SPEC
    assert grid.data[cells_of((1.02, 3.0))] == OCC_OCCUPIED and grid.data[cells_of((1.08, 0.3))] == OCC_OCCUPIED
    assert grid.data[cells_of((2.0, 3.0))] == 0  # free in the file
    assert grid.data[cells_of((4.5, 5.5))] == OCC_UNKNOWN  # unknown in the file
    assert grid.data[cells_of((7.0, 1.0))] == OCC_UNKNOWN  # outside the file
    assert grid.data[cells_of((5.5, 3.0))] == OCC_OCCUPIED  # the box, half over the file's free cells
    assert grid.data[cells_of((4.98, 3.0))] == 0 and grid.data[cells_of((5.02, 3.0))] == OCC_OCCUPIED

    with pytest.warns(InputWarning, match=r"0.1 m cells sampled onto the scenario's 0.05 m cells"):
        loaded = scenario([BOX], goal=(3.0, 3.0), base_dir=tmp_path, static_map="room.yaml")
    layered = build_costmap(loaded, social=False)
    master = layered.master.costs
    assert master[cells_of((5.5, 3.0))] == LETHAL and master[cells_of((1.05, 5.0))] == LETHAL
    assert master[cells_of((3.0, 3.0))] == FREE_SPACE
    assert master[cells_of((4.5, 5.5))] == FREE_SPACE  # unknown in the file, free: unknown space is not tracked


def test_unknown_space_stays_unknown_where_no_beam_reached_but_the_box_is_lethal():
    data = scenario([BOX], layers={"obstacle": {"track_unknown_space": True}})
    layered = build_costmap(data, social=False)
    master = layered.master.costs
    assert master[cells_of((5.5, 3.0))] == LETHAL and master[cells_of((6.0, 3.0))] == LETHAL
    assert master[cells_of((7.0, 3.0))] == NO_INFORMATION  # behind the box: unknown, as before
    assert master[cells_of((2.0, 3.0))] == FREE_SPACE  # seen free


def test_without_a_static_layer_in_the_plugins_the_obstacles_are_only_what_the_scan_sees():
    layered = build_costmap(scenario([BOX], layers={"plugins": ["lidar", "inflation"]}), social=False)
    assert list(layered.grids) == ["lidar", "inflation"]
    assert layered.master.costs[cells_of((6.0, 3.0))] != LETHAL


@pytest.mark.parametrize(
    ("obstacles", "message"),
    [
        (
            [{"type": "box", "min": [8.0, 2.0], "max": [9.5, 4.0]}],
            "no path: goal (9.00, 3.00) is in collision: it lies inside an obstacle (cell cost 254, lethal)",
        ),
        (
            [{"type": "segment", "points": [[8.0, 2.0], [9.6, 2.0], [9.6, 4.0], [8.0, 4.0], [8.0, 2.0]]}],
            "no path: the start and the goal lie in separate free regions",
        ),
        ([{"type": "circle", "center": [9.0, 3.0], "radius": 0.2}], "no path: goal (9.00, 3.00) is in collision"),
    ],
)
def test_a_goal_inside_a_box_or_walled_in_is_refused(obstacles, message):
    s = scenario(obstacles)
    problem = planning_problem(s, build_costmap(s, social=False).master)
    with pytest.raises(PlanningError) as caught:
        plan(problem, "grid")
    assert message in str(caught.value)


def test_a_wall_along_the_maps_border_is_in_its_outer_cells_on_every_side():
    """A room drawn on the map's bounds: the walls on the upper and right borders would fall in the cells above and
    to the right of the map, outside it; they are in the last row and column instead, as the other two are in the
    first, and the robot keeps its radius from all four."""
    room = [[0.0, 0.0], [10.0, 0.0], [10.0, 6.0], [0.0, 6.0], [0.0, 0.0]]
    mask = obstacle_mask([SegmentObstacle(tuple(map(tuple, room)))], SPEC)
    for edge in (mask[0], mask[-1], mask[:, 0], mask[:, -1]):
        assert edge.all()
    assert mask.sum() == 2 * (SPEC.width + SPEC.height) - 4  # the border cells only
    master = build_costmap(scenario([{"type": "segment", "points": room}]), social=False).master.costs
    assert (master[-1] == LETHAL).all() and (master[:, -1] == LETHAL).all()
    assert (master[-5] >= 253).all() and (master[:, -5] >= 253).all()  # 0.25 m of the robot's radius inscribed


@pytest.mark.parametrize(("resolution", "cells"), [(0.07, (86, 57)), (0.3, (20, 13))])
def test_a_wall_on_the_declared_border_of_a_map_of_no_whole_number_of_cells_is_in_its_last_row(resolution, cells):
    """A 6 x 4 m map of 0.07 m cells has 57 rows, 3.99 m: a wall along y = 4 lay outside the grid, lost, and the
    simulated robot hit it; up to half a cell beyond the grid's edge it is in the last row (column)."""
    spec = GridSpec.from_size(resolution, (0.0, 0.0), (6.0, 4.0))
    assert (spec.width, spec.height) == cells
    mask = obstacle_mask([SegmentObstacle(((0.0, 4.0), (6.0, 4.0))), SegmentObstacle(((6.0, 0.0), (6.0, 4.0)))], spec)
    assert mask[-1].all() and mask[:, -1].all()
    beyond = obstacle_mask([SegmentObstacle(((0.0, spec.bounds[3] + resolution * 0.6), (6.0, 5.0)))], spec)
    assert not beyond[-1].any()  # more than half a cell beyond: outside the map, as before


def test_a_person_standing_in_an_obstacle_is_warned_of_and_drawn_as_given():
    """A person inside a box or on a wall's cells stands where nobody can: the people and the map are likely in
    different frames. sid plan and sid costmap drew such a scene without a word (sid simulate refuses it)."""
    wall = {"type": "segment", "points": [[0.5, 5.0], [9.5, 5.0]]}
    people = [{"id": 1, "x": 5.5, "y": 3.0, "theta": 0.0}, {"id": 2, "x": 3.0, "y": 5.0}, {"id": 3, "x": 8.0, "y": 1.0}]
    with pytest.warns(InputWarning) as said:
        layered = build_costmap(scenario([BOX, wall], people=people))
    messages = [str(w.message) for w in said if "occupied cell" in str(w.message)]
    assert messages == [
        "people[0]: person 1 at (5.5, 3) stands in an occupied cell of the known map (an obstacle or the static_map "
        "file's walls): are the people and the map in one frame?",
        "people[1]: person 2 at (3, 5) stands in an occupied cell of the known map (an obstacle or the static_map "
        "file's walls): are the people and the map in one frame?",
    ]
    assert len(layered.inputs[PEOPLE]) == 3  # drawn as given
