"""The obstacle (LiDAR) layer: marking and clearing, ranges, incremental ray tracing, people's marks, its windows."""

from __future__ import annotations

import numpy as np
import pytest

from costmap.grid import FREE_SPACE, LETHAL, NO_INFORMATION, GridSpec
from costmap.layer import LayerInputs
from costmap.layers.obstacle import SCAN, ObstacleLayer, ObstacleParams, trace_cells
from costmap.layers.social import PEOPLE
from costmap.scan import LaserScan
from sid.perception.people import Person
from sid.scenario.known_map import obstacle_mask
from sid.scenario.lidar import simulate_scan
from sid.scenario.obstacles import SegmentObstacle
from tests.costmap.scenes import WALLS

SPEC = GridSpec.from_size(0.05, (-1.0, -4.0), (10.0, 8.0))


def test_lidar_layer_marks_hits_and_clears_the_rays():
    spec = GridSpec(0.05, 0.0, 0.0, 100, 100)
    layer = ObstacleLayer(spec, ObstacleParams(track_unknown_space=True))
    scan = LaserScan(np.array([2.0, np.inf, np.nan]), 0.0, np.pi / 2, 4.0, (1.0, 1.0, 0.0))
    layer.apply_scan(scan)
    hit = spec.world_to_cell([[3.0, 1.0]])[0]
    assert layer.costs[hit[0], hit[1]] == LETHAL
    ray = spec.world_to_cell([[1.0 + t, 1.0] for t in np.arange(0.0, 1.95, 0.05)])
    assert (layer.costs[ray[:, 0], ray[:, 1]] == FREE_SPACE).all()
    up = spec.world_to_cell([[1.0, 1.0 + t] for t in np.arange(0.1, 3.9, 0.05)])  # inf beam: cleared, not marked
    assert (layer.costs[up[:, 0], up[:, 1]] == FREE_SPACE).all()
    left = spec.world_to_cell([[0.5, 1.0]])[0]  # nan beam (pointing -x... here +pi): untouched
    assert layer.costs[left[0], left[1]] == NO_INFORMATION
    assert (layer.costs == LETHAL).sum() == 1


def test_lidar_layer_respects_obstacle_and_raytrace_ranges():
    spec = GridSpec(0.05, 0.0, 0.0, 200, 40)
    layer = ObstacleLayer(
        spec, ObstacleParams(obstacle_max_range=2.5, raytrace_max_range=3.0, track_unknown_space=True)
    )
    layer.apply_scan(LaserScan(np.array([5.0]), 0.0, 0.01, 10.0, (0.5, 1.0, 0.0)))
    assert not (layer.costs == LETHAL).any()  # 5 m > obstacle_max_range
    row = layer.costs[20]
    assert (row[10:69] == FREE_SPACE).all() and (row[75:] == NO_INFORMATION).all()


def test_lidar_layer_retraces_only_moved_beams_and_counts_the_beams_of_a_fresh_trace():
    rng = np.random.default_rng(3)
    layer = ObstacleLayer(SPEC)
    origin = np.array([4.0, 0.0])
    ends = origin + rng.normal(0.0, 4.0, (360, 2))
    previous = None
    for _ in range(8):  # some beams move their end cell, one scan gets longer, then the sensor moves (1 cm a step)
        moved = rng.random(len(ends)) < 0.2
        ends[moved] += rng.normal(0.0, 0.3, 2)
        traced, everything = layer._beams.update(origin, ends)
        cell = SPEC.world_to_cell(origin[None])[0].tolist()
        fresh = trace_cells(SPEC, origin, ends)
        counts = np.bincount(fresh, minlength=SPEC.width * SPEC.height)
        np.testing.assert_array_equal(layer._beams.coverage, counts)
        assert everything == (cell != previous)  # all beams again when the sensor's cell changed
        assert np.isin(traced, fresh).all() and (everything or len(traced) < len(fresh))
        ends[0] = origin + (20.0, 0.5)
        origin, previous = origin + (0.01, 0.0), cell


@pytest.mark.parametrize("seed", range(4))
def test_lidar_layer_writes_what_clearing_every_beam_then_marking_would(seed):
    # Nav2's order written out plainly (every beam cleared, then every hit marked, then the people's marks cleared)
    # against the layer's incremental writes, over scans where people walk and the sensor sometimes moves.
    rng = np.random.default_rng(seed)
    walls = [SegmentObstacle(((-1.0, 2.5), (9.0, 2.5))), SegmentObstacle(((8.0, -3.5), (8.0, 3.5)))]
    layer = ObstacleLayer(SPEC, ObstacleParams(track_unknown_space=bool(seed % 2)), people_clear_radius=0.3)
    expected = np.full(SPEC.shape, layer.costs[0, 0])
    people = [Person(k, x, y, 0.0) for k, (x, y) in enumerate(rng.uniform((1.0, -2.0), (7.0, 2.0), (4, 2)))]
    pose = (0.0, 0.0, 0.0)
    for step in range(12):
        if step % 5 == 4:  # the sensor moves to another cell
            pose = (pose[0] + 0.3, pose[1] + 0.1, pose[2])
        elif step % 5 == 2:  # it turns in its cell: most beams' end cells move
            pose = (pose[0], pose[1], pose[2] + 0.01)
        people = [Person(p.id, p.x + rng.normal(0, 0.05), p.y + rng.normal(0, 0.05), 0.0) for p in people]
        scan = simulate_scan(pose, walls, people, beams=360, range_max=10.0)
        before = layer.costs.copy()
        window = layer.update(LayerInputs({PEOPLE: people, SCAN: scan}), None)
        r = scan.valid_ranges()  # no return (inf): cleared to the 10 m raytrace range, not marked
        origin = np.array(pose[:2])
        clear_to = np.where(np.isinf(r), 10.0, r + 1e-4 * SPEC.resolution)  # a hit's cell: 1e-4 cells along its beam
        ends = origin + scan.directions * clear_to[:, None]
        hits = SPEC.world_to_cell(ends[np.isfinite(r)])
        hits = hits[SPEC.in_bounds(hits)]
        expected.ravel()[trace_cells(SPEC, origin, ends)] = FREE_SPACE
        expected[hits[:, 0], hits[:, 1]] = LETHAL
        xs, ys = SPEC.cell_centres()
        near = np.zeros(SPEC.shape, dtype=bool)
        for p in people:
            near |= np.hypot(xs - p.x, ys - p.y) <= 0.3
        expected[near & (expected == LETHAL)] = FREE_SPACE
        np.testing.assert_array_equal(layer.costs, expected)
        changed = np.argwhere(before != layer.costs)
        if window is None:
            assert len(changed) == 0
        else:  # the smallest window holding every changed cell
            assert (changed.min(axis=0).tolist(), (changed.max(axis=0) + 1).tolist()) == (
                [window.row0, window.col0],
                [window.row1, window.col1],
            )


def test_lidar_layer_reports_only_what_changed():
    people = [Person(1, 4.0, 0.0, np.pi)]
    layer = ObstacleLayer(SPEC, people_clear_radius=0.3)
    scan = simulate_scan((0.0, 0.0, 0.0), [SegmentObstacle(((-1.0, 2.5), (9.0, 2.5)))], people, beams=720)
    scene = LayerInputs({PEOPLE: people, SCAN: scan})
    assert layer.update(scene, None) is not None
    assert layer.update(scene, None) is None  # the same scene again: nothing changed
    moved = [Person(1, 4.0, -1.0, np.pi)]
    window = layer.update(
        LayerInputs({PEOPLE: moved, SCAN: simulate_scan((0.0, 0.0, 0.0), [], moved, beams=720)}), None
    )
    assert window is not None  # the wall is gone: its marks were cleared, only there
    assert window.row0 <= SPEC.world_to_cell([[0.0, 2.5]])[0, 0] < window.row1
    assert window.row0 >= SPEC.world_to_cell([[0.0, 2.0]])[0, 0]


def test_lidar_layer_rejects_a_sensor_outside_the_map():
    layer = ObstacleLayer(SPEC)
    with pytest.raises(ValueError, match="outside the costmap"):
        layer.apply_scan(LaserScan(np.array([1.0]), 0.0, 0.1, 5.0, (50.0, 0.0, 0.0)))


def test_the_lidar_layer_clears_people_marks_by_its_own_parameter():
    people = [Person(1, 4.0, 0.0, np.pi)]
    scan = simulate_scan((0.0, 0.0, 0.0), WALLS, people, beams=720)
    near = SPEC.window((3.5, -0.5), (4.5, 0.5))
    for radius, marks in ((0.0, True), (0.3, False)):
        layer = ObstacleLayer(SPEC, people_clear_radius=radius)
        window = layer.update(LayerInputs({PEOPLE: people, SCAN: scan}), None)
        assert ((layer.costs[near.slices] == LETHAL).any()) == marks
        assert (layer.costs == LETHAL).any() and window is not None
        no_scan = LayerInputs({PEOPLE: people})
        assert layer.update(no_scan, None) is None  # no scan and nothing left to clear: no change
        mark = SPEC.window((4.1, 0.05), (4.1, 0.05))
        assert mark is not None
        layer.costs[mark.slices] = LETHAL  # within 0.3 m of the person: theirs when the layer clears people's marks
        assert layer.update(no_scan, None) == (None if radius == 0 else mark)  # the window of what changed
    with pytest.raises(ValueError, match="people_clear_radius"):
        ObstacleLayer(SPEC, people_clear_radius=-1.0)


@pytest.mark.parametrize("y", [0.8, 0.35, -0.35])
def test_a_wall_on_a_cell_border_is_marked_in_the_cell_the_static_layer_puts_it_in(y: float) -> None:
    # A wall along y on 0.05 m cells lies on a border: the known map puts it in the cell above, the one a beam from
    # below enters. Computed hits came out at 0.7999... for about half the beams and marked the free cell before it,
    # walling off a corridor the map leaves open. Seen from below (the sensor under the wall) every hit is the
    # wall's cell; from above, the cell beyond the surface, never one on the sensor's side of the wall.
    spec = GridSpec.from_size(0.05, (0.0, -1.0), (10.0, 2.0))
    wall = SegmentObstacle(((0.0, y), (10.0, y)))
    static = obstacle_mask([wall], spec)
    wall_rows = np.unique(np.nonzero(static)[0])
    for sensor_y in (y - 0.15, y + 0.15):
        layer = ObstacleLayer(spec)
        layer.apply_scan(simulate_scan((5.0, sensor_y, 0.0), [wall], [], beams=720, range_max=10.0))
        rows = np.unique(np.nonzero(layer.costs == LETHAL)[0])
        below = sensor_y < y
        assert rows.tolist() == (wall_rows.tolist() if below else [wall_rows[0] - 1])
