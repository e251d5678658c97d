"""Costmap layers: Nav2 inflation, LiDAR marking/clearing, the social layer, combination and people updates."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from costmap.combine import combine
from costmap.grid import FREE_SPACE, INSCRIBED, LETHAL, NO_INFORMATION, Costmap2D, GridSpec, Window
from costmap.layer import LayerInputs
from costmap.layered import LayeredCostmap
from costmap.layers.inflation import InflationLayer, InflationParams, distance_to_lethal_cells
from costmap.layers.obstacle import ObstacleLayer, ObstacleParams
from costmap.layers.social import (
    SocialLayer,
    SocialParams,
    group_zone_polygon,
    paint_bodies,
    paint_body,
    paint_group,
    paint_groups,
    paint_people,
    paint_person,
    zone_hull,
)
from costmap.plugins import CostmapParams, layered_costmap
from costmap.scan import LaserScan
from sid.perception.group import Group
from sid.perception.people import Person
from sid.scenario.lidar import simulate_scan
from sid.scenario.obstacles import BoxObstacle, CircleObstacle, SegmentObstacle

SPEC = GridSpec.from_size(0.05, (-1.0, -4.0), (10.0, 8.0))


def nav2_cost(d_m: float, inscribed: float, k: float) -> int:
    """Nav2's InflationLayer::computeCost written out by hand for one distance."""
    if d_m == 0:
        return 254
    if d_m <= inscribed:
        return 253
    return int(252 * np.exp(-k * (d_m - inscribed)))


def triad() -> tuple[list[Person], Group]:
    """Three people 0.6 m around (4, 0), facing the centre, and their group (o-space = small triangle)."""
    angles = np.deg2rad([90, 210, 330])
    people = [Person(i + 1, 4 + 0.6 * np.cos(a), 0.6 * np.sin(a), float(a + np.pi), 1.0) for i, a in enumerate(angles)]
    zone = np.array([[4.0, 0.2], [3.83, -0.1], [4.17, -0.1]])
    return people, Group((1, 2, 3), (4.0, 0.0), 0.05, zone, 0.6)


# --- inflation --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("radius,k,resolution", [(0.55, 10.0, 0.05), (1.0, 3.0, 0.1), (0.3, 25.0, 0.025)])
def test_inflation_around_one_lethal_cell_is_nav2_formula_everywhere_within_radius(radius, k, resolution):
    spec = GridSpec(resolution, 0.0, 0.0, 81, 81)
    master = np.zeros(spec.shape, dtype=np.uint8)
    master[40, 40] = LETHAL
    layer = InflationLayer(spec, InflationParams(radius, k), inscribed_radius=0.25)
    layer.write(master, spec.whole)
    rows, cols = np.indices(spec.shape)
    d = np.hypot(rows - 40, cols - 40) * resolution
    within = d <= radius
    expected = np.array([nav2_cost(v, 0.25, k) for v in d[within]])
    assert within.sum() > 20
    np.testing.assert_array_equal(master[within], expected)
    np.testing.assert_array_equal(layer.costs[within], expected)
    # Nav2 reaches ceil(radius / resolution) cells; nothing beyond that.
    reach = np.hypot(rows - 40, cols - 40) > layer.cell_radius
    assert not master[reach].any()


def test_inflation_reach_rounds_up_like_nav2_cell_distance():
    spec = GridSpec(0.05, 0.0, 0.0, 41, 41)
    master = np.zeros(spec.shape, dtype=np.uint8)
    master[20, 20] = LETHAL
    layer = InflationLayer(spec, InflationParams(inflation_radius=0.53), inscribed_radius=0.25)
    layer.write(master, spec.whole)
    assert layer.cell_radius == 11  # ceil(0.53 / 0.05): the reach is 0.55 m, beyond the 0.53 m asked for
    assert master[20, 31] == nav2_cost(0.55, 0.25, 10.0) > 0
    assert master[20, 32] == 0


def test_opencv_and_scipy_distances_agree():
    rng = np.random.default_rng(0)
    lethal = rng.random((120, 90)) < 0.01
    a = distance_to_lethal_cells(lethal, "opencv")
    b = distance_to_lethal_cells(lethal, "scipy")
    np.testing.assert_allclose(a, b, atol=1e-4)
    with pytest.raises(ValueError, match="distance method"):
        distance_to_lethal_cells(lethal, "manhattan")


def test_inflation_keeps_the_larger_cost_and_nav2_unknown_rule():
    spec = GridSpec(0.05, 0.0, 0.0, 41, 41)
    master = np.zeros(spec.shape, dtype=np.uint8)
    master[20, 20] = LETHAL
    master[20, 30] = 250  # already more than inflation gives 10 cells away
    master[20, 22] = NO_INFORMATION  # 0.10 m away: inscribed, replaces unknown
    master[20, 28] = NO_INFORMATION  # 0.40 m away: graded, unknown stays unknown
    InflationLayer(spec, InflationParams(0.55), inscribed_radius=0.25).write(master, spec.whole)
    assert master[20, 30] == 250
    assert master[20, 22] == INSCRIBED
    assert master[20, 28] == NO_INFORMATION
    master2 = np.zeros(spec.shape, dtype=np.uint8)
    master2[20, 20], master2[20, 28] = LETHAL, NO_INFORMATION
    InflationLayer(spec, InflationParams(0.55, inflate_unknown=True), 0.25).write(master2, spec.whole)
    assert master2[20, 28] == nav2_cost(0.40, 0.25, 10.0)


def test_inflation_recomputed_around_changes_equals_a_whole_map_inflation():
    """A layer recomputes only around lethal cells that appeared or disappeared. Over a sequence in which the master
    changes only inside each write's window (as ``LayeredCostmap`` does): blobs that appear, move, vanish and touch
    the map's edges, far apart and close together, and a wall that comes and goes, the layer's grid always equals
    that of a new layer inflating the whole map."""
    rng = np.random.default_rng(5)
    spec = GridSpec.from_size(0.05, (0.0, 0.0), (12.0, 9.0))
    layer = InflationLayer(spec, InflationParams(), inscribed_radius=0.22)
    master = np.zeros(spec.shape, np.uint8)
    for step in range(16):
        r0, c0 = rng.integers(0, spec.height - 10), rng.integers(0, spec.width - 10)
        r1, c1 = r0 + rng.integers(10, 90), c0 + rng.integers(10, 120)
        window = Window(int(r0), int(min(r1, spec.height)), int(c0), int(min(c1, spec.width)))
        view = master[window.slices]
        view[rng.random(view.shape) < 0.3] = FREE_SPACE  # some marks vanish, others appear
        view[rng.random(view.shape) < 0.01] = LETHAL
        if step % 5 == 0:
            view[:, :3] = LETHAL if step % 10 == 0 else FREE_SPACE  # a wall segment comes and goes
        layer.write(master.copy(), window)
        fresh = InflationLayer(spec, InflationParams(), inscribed_radius=0.22)
        fresh.write(master.copy(), spec.whole)
        np.testing.assert_array_equal(layer.costs, fresh.costs)


def test_inflation_without_lethal_cells_is_zero():
    layer = InflationLayer(SPEC, InflationParams(), inscribed_radius=0.25)
    master = np.full(SPEC.shape, 100, dtype=np.uint8)
    layer.write(master, SPEC.whole)
    assert (master == 100).all() and not layer.costs.any()


# --- combination ------------------------------------------------------------------------------------------


def test_combination_methods_follow_nav2():
    master = np.array([0, 100, 255, 200, 250], dtype=np.uint8)
    layer = np.array([50, 255, 30, 100, 10], dtype=np.uint8)
    out = master.copy()
    combine(out, layer, "max")
    assert out.tolist() == [50, 100, 30, 200, 250]
    out = master.copy()
    combine(out, layer, "overwrite")
    assert out.tolist() == [50, 100, 30, 100, 10]
    out = master.copy()
    combine(out, layer, "true_overwrite")
    assert out.tolist() == layer.tolist()
    out = master.copy()
    combine(out, layer, "addition")
    assert out.tolist() == [50, 100, 30, 252, 252]
    master = np.array([0, 255, 255, 255, 10, 10], dtype=np.uint8)
    layer = np.array([5, 100, 253, 254, 0, 40], dtype=np.uint8)
    out = master.copy()
    combine(out, layer, "max_keep_unknown")  # Nav2's inflation rule: only >= 253 replaces unknown
    assert out.tolist() == [5, 255, 253, 254, 10, 40]
    with pytest.raises(ValueError, match="combination method"):
        combine(out, layer, "min")


def test_max_can_skip_a_layer_value_that_carries_no_opinion():
    master = np.array([255, 255, 10, 10], dtype=np.uint8)
    combine(master, np.array([0, 40, 0, 40], dtype=np.uint8), "max_nonzero")
    assert master.tolist() == [255, 40, 10, 40]  # a zero social cell does not turn unknown into free


@pytest.mark.parametrize("method", ["max", "max_nonzero", "max_keep_unknown"])
def test_max_combinations_equal_nav2_rules_written_out_on_every_pair_of_values(method):
    # every (master, layer) pair of uint8 values, then windows of it with no unknown master or layer cell (the
    # plain-max path) and with some, an empty one, and a strided one (numpy's path)
    values = np.arange(256, dtype=np.uint8)
    master, layer = np.meshgrid(values, values)
    larger = np.maximum(master, layer)
    unknown = master == NO_INFORMATION
    if method == "max_keep_unknown":
        expected = np.where(unknown & (layer >= INSCRIBED), layer, larger)
    else:
        no_opinion = NO_INFORMATION if method == "max" else FREE_SPACE
        expected = np.where(layer == no_opinion, master, np.where(unknown, layer, larger))
    windows = [(slice(None), slice(None)), (slice(0, 255), slice(0, 255)), (slice(3, 90), slice(7, 255))]
    for rows, cols in [*windows, (slice(0, 0), slice(None)), (slice(None, None, 3), slice(None, None, -2))]:
        out = master.copy()
        combine(out[rows, cols], layer[rows, cols], method)
        np.testing.assert_array_equal(out[rows, cols], expected[rows, cols])
        out[rows, cols] = master[rows, cols]
        np.testing.assert_array_equal(out, master)  # nothing outside the window


# --- simulated scan and the LiDAR layer ---------------------------------------------------------------------


def test_simulated_scan_hits_walls_circles_boxes_and_people_at_the_right_range():
    obstacles = [
        SegmentObstacle(((3.0, -5.0), (3.0, 5.0))),
        CircleObstacle((0.0, 2.0), 0.5),
        BoxObstacle((-3.0, -1.0), (-2.0, 1.0)),
    ]
    people = [Person(1, 0.0, -1.5)]
    scan = simulate_scan((0.0, 0.0, 0.0), obstacles, people, beams=360, range_max=10.0, body_radius=0.2)
    angles = scan.angles
    r = dict(zip(np.round(np.rad2deg(angles)).astype(int), scan.ranges, strict=True))
    assert r[0] == pytest.approx(3.0)  # the wall
    assert r[45] == pytest.approx(3.0 * np.sqrt(2))
    assert r[90] == pytest.approx(1.5)  # circle surface
    assert r[-180] == pytest.approx(2.0)  # box face
    assert r[-90] == pytest.approx(1.3)  # body surface


def test_simulated_scan_reports_no_return_as_inf():
    scan = simulate_scan((0.0, 0.0, 0.0), [SegmentObstacle(((5.0, -1.0), (5.0, 1.0)))], beams=8, range_max=4.0)
    assert np.isinf(scan.ranges).all()


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
    from costmap.layers.obstacle import trace_cells

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
    from costmap.layers.obstacle import trace_cells

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
        window = layer.update(LayerInputs(people, (), scan), None)
        r = scan.valid_ranges()  # no return (inf): cleared to the 10 m raytrace range, not marked
        origin = np.array(pose[:2])
        clear_to = np.where(np.isinf(r), 10.0, r)
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
    assert layer.update(LayerInputs(people, (), scan), None) is not None
    assert layer.update(LayerInputs(people, (), scan), None) is None  # the same scene again: nothing changed
    moved = [Person(1, 4.0, -1.0, np.pi)]
    window = layer.update(LayerInputs(moved, (), simulate_scan((0.0, 0.0, 0.0), [], moved, beams=720)), None)
    assert window is not None  # the wall is gone: its marks were cleared, only there
    assert window.row0 <= SPEC.world_to_cell([[0.0, 2.5]])[0, 0] < window.row1
    assert window.row0 >= SPEC.world_to_cell([[0.0, 2.0]])[0, 0]


def test_lidar_layer_rejects_a_sensor_outside_the_map():
    layer = ObstacleLayer(SPEC)
    with pytest.raises(ValueError, match="outside the costmap"):
        layer.apply_scan(LaserScan(np.array([1.0]), 0.0, 0.1, 5.0, (50.0, 0.0, 0.0)))


def test_scan_rejects_nan_pose():
    with pytest.raises(ValueError, match="pose"):
        LaserScan(np.array([1.0]), 0.0, 0.1, 5.0, (np.nan, 0.0, 0.0))
    with pytest.raises(ValueError, match="pose"):
        simulate_scan((0.0, np.nan, 0.0), [])


# --- social layer ------------------------------------------------------------------------------------------


def test_group_zone_covers_members_and_the_space_between_them():
    people, group = triad()
    poly = group_zone_polygon(group, people)
    for a in people:
        assert poly.contains(shapely.Point(a.x, a.y))
        for b in people:  # the segment between two members lies inside (p-space)
            for t in np.linspace(0, 1, 11):
                assert poly.covers(shapely.Point(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)))
    assert poly.contains(shapely.Point(*group.interest_point))
    assert group_zone_polygon(group, {p.id: p for p in people}).equals(poly)


def test_group_zone_of_a_pair_is_a_proper_polygon_and_missing_members_are_named():
    people = [Person(1, 0.0, 0.0, 0.0), Person(2, 1.0, 0.0, np.pi)]
    pair = Group((1, 2), (0.5, 0.0), 0.0, np.array([[0.5, 0.0]]), 0.5)
    assert group_zone_polygon(pair, people).area > 0
    assert group_zone_polygon(pair, people, margin=0.0).equals(shapely.LineString([(0, 0), (1, 0)]))  # no area
    with pytest.raises(ValueError, match=r"members \[2\]"):
        group_zone_polygon(pair, people[:1])


def test_every_cell_inside_the_group_zone_costs_at_least_group_cost():
    people, group = triad()
    params = SocialParams()
    layer = SocialLayer(SPEC, params)
    layer.update(LayerInputs(people, [group]), None)
    xs, ys = SPEC.cell_centres()
    inside = shapely.contains_xy(group_zone_polygon(group, people, params.group_margin), xs, ys)
    assert inside.sum() > 300
    assert (layer.costs[inside] >= params.group_cost).all()
    assert layer.costs.max() == LETHAL  # bodies only
    assert not np.isin(layer.costs, [INSCRIBED, NO_INFORMATION]).any()
    assert (layer.costs[layer.costs != LETHAL] <= 252).all()


def test_personal_space_is_larger_in_front_and_circular_without_orientation():
    layer = SocialLayer(SPEC, SocialParams())
    layer.update(LayerInputs([Person(1, 2.0, 0.0, 0.0), Person(2, 6.0, 0.0, None)]), None)
    costmap = Costmap2D(SPEC, layer.costs)
    front, back = costmap.cost_at([[2.8, 0.0], [1.2, 0.0]])
    assert front > back > 0
    left, right = costmap.cost_at([[2.0, 0.6], [2.0, -0.6]])
    assert left == right
    around = costmap.cost_at([[6.6, 0.0], [5.4, 0.0], [6.0, 0.6], [6.0, -0.6]])
    assert len(set(around.tolist())) == 1 and around[0] > 0


@pytest.mark.parametrize("theta", [None, 0.0, 0.7, -2.9, np.pi / 2])
def test_personal_space_is_the_float64_gaussian_to_one_cost_unit(theta):
    # float32 and OpenCV's exp: never more than 1 unit from floor(amplitude exp(-(u^2 / 2 su^2 + v^2 / 2 sv^2)))
    # in float64, and equal at all but a handful of cells.
    params = SocialParams()
    person = Person(1, 3.013, 0.487, theta)
    costs = np.zeros(SPEC.shape, dtype=np.uint8)
    window = paint_person(costs, SPEC, person, params)
    assert window is not None
    xs, ys = SPEC.cell_axes(window)
    dx, dy = xs - person.x, ys - person.y
    if theta is None:
        exponent = -(dx**2 + dy**2) / (2 * params.sigma_unknown**2)
    else:
        u, v = np.cos(theta) * dx + np.sin(theta) * dy, np.cos(theta) * dy - np.sin(theta) * dx
        sigma_u = np.where(u >= 0, params.sigma_front, params.sigma_rear)
        exponent = -(u**2 / (2 * sigma_u**2) + v**2 / (2 * params.sigma_side**2))
    expected = np.floor(params.amplitude * np.exp(exponent))
    difference = np.abs(costs[window.slices].astype(int) - expected)
    assert difference.max() <= 1 and np.count_nonzero(difference) <= 3
    outside = np.ones(SPEC.shape, dtype=bool)
    outside[window.slices] = False
    assert not costs[outside].any() and expected[0].max() <= 1 and expected[:, 0].max() <= 1  # the window holds it


@pytest.mark.parametrize(
    ("theta", "sigma_front", "sigma_rear"),
    [(0.7, 0.8, 0.4), (2.4, 2.2, 0.4), (-1.1, 0.5, 0.9), (np.pi / 4, 0.8, 0.8), (-3.0, 3.5, 0.3)],
)
def test_personal_space_holds_the_float64_gaussian_for_any_spread_ahead_or_behind(theta, sigma_front, sigma_rear):
    # A walker's stretched front (the tracked layer's sigma_front), a rear wider than the front, equal halves: the
    # whole grid within 1 cost unit of the float64 formula, nothing painted outside the window it returns.
    params = SocialParams(sigma_rear=sigma_rear)
    person = Person(1, 4.21, -0.37, theta)
    costs = np.zeros(SPEC.shape, dtype=np.uint8)
    window = paint_person(costs, SPEC, person, params, sigma_front)
    assert window is not None
    xs, ys = SPEC.cell_centres()
    dx, dy = xs - person.x, ys - person.y
    u, v = np.cos(theta) * dx + np.sin(theta) * dy, np.cos(theta) * dy - np.sin(theta) * dx
    sigma_u = np.where(u >= 0, sigma_front, sigma_rear)
    expected = np.floor(params.amplitude * np.exp(-(u**2 / (2 * sigma_u**2) + v**2 / (2 * params.sigma_side**2))))
    difference = np.abs(costs.astype(int) - expected)
    assert difference.max() <= 1 and np.count_nonzero(difference) <= 3
    outside = np.ones(SPEC.shape, dtype=bool)
    outside[window.slices] = False
    assert not costs[outside].any()


@pytest.mark.parametrize(
    "hull",
    [
        zone_hull(triad()[1], triad()[0]),  # a group's zone
        shapely.Point(3.02, 0.41),
        shapely.LineString([(2.0, -1.0), (3.3, 0.7)]),
        shapely.box(5.0, -1.0, 5.8, 1.5),
    ],
    ids=["zone", "point", "segment", "box"],
)
def test_the_group_fall_off_is_the_float64_gaussian_of_the_distance_to_the_hull_to_one_cost_unit(hull):
    params = SocialParams()
    costs = np.zeros(SPEC.shape, dtype=np.uint8)
    window = paint_group(costs, SPEC, hull, params)
    assert window is not None
    xs, ys = SPEC.cell_axes(window)
    distance = shapely.distance(hull, shapely.points(*np.broadcast_arrays(xs, ys)))
    beyond = np.maximum(distance - params.group_margin, 0.0)
    expected = np.floor(params.group_cost * np.exp(-(beyond**2) / (2 * params.group_sigma**2)))
    difference = np.abs(costs[window.slices].astype(int) - expected)
    assert difference.max() <= 1 and np.count_nonzero(difference) <= 3


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_people_groups_and_bodies_painted_together_equal_each_painted_alone(seed):
    # The batched painting (a common block per batch, several batches when windows differ in size) writes what
    # painting each alone writes, to the bit, and returns the same windows; people and hulls beyond the edges too.
    rng = np.random.default_rng(seed)
    params = SocialParams()
    people = [
        Person(i, float(rng.uniform(-2.0, 10.0)), float(rng.uniform(-5.0, 5.0)), [None, *rng.uniform(-4, 4, 4)][i % 5])
        for i in range(12)
    ]
    fronts = [float(f) for f in rng.choice([0.3, 0.8, 2.5], len(people))]  # stretched walkers: several batches
    hulls = [
        shapely.Point(*rng.uniform(-1.5, 9.5, 2)),
        shapely.LineString(rng.uniform(0.0, 8.0, (2, 2))),
        *(
            shapely.MultiPoint(rng.uniform(-0.8, 0.8, (n, 2)) + rng.uniform(-1.5, 9.5, 2)).convex_hull
            for n in (3, 5, 9)
        ),
        shapely.box(1.0, -1.0, 6.0, 0.5),  # a large zone beside small ones
    ]
    for one, together in [
        (lambda c: [paint_person(c, SPEC, p, params, f) for p, f in zip(people, fronts, strict=True)],
         lambda c: paint_people(c, SPEC, people, params, fronts)),
        (lambda c: [paint_person(c, SPEC, p, params) for p in people], lambda c: paint_people(c, SPEC, people, params)),
        (lambda c: [paint_group(c, SPEC, h, params) for h in hulls], lambda c: paint_groups(c, SPEC, hulls, params)),
        (lambda c: [paint_body(c, SPEC, p, 0.23) for p in people], lambda c: paint_bodies(c, SPEC, people, 0.23)),
    ]:  # fmt: skip
        alone, batched = np.zeros(SPEC.shape, dtype=np.uint8), np.zeros(SPEC.shape, dtype=np.uint8)
        assert one(alone) == together(batched)
        assert alone.any() and np.array_equal(alone, batched)


def test_social_layer_clips_people_outside_the_map():
    layer = SocialLayer(SPEC, SocialParams())
    layer.update(LayerInputs([Person(1, 9.3, 0.0, np.pi)]), None)  # 0.3 m beyond the right edge, facing into the map
    assert layer.costs[:, -1].max() > 0
    assert not (layer.costs == LETHAL).any()  # the body itself is outside


# --- the layered costmap and people updates -------------------------------------------------------------------


def social_costmap(social: bool = True) -> LayeredCostmap:
    """The default layers on SPEC (no static map), with or without the social layer."""
    return layered_costmap(SPEC, CostmapParams() if social else CostmapParams().without("social"))


def scan_of(people, pose=(0.0, 0.0, 0.0)):
    return simulate_scan(pose, [SegmentObstacle(((-1.0, 2.5), (9.0, 2.5)))], people, beams=720, range_max=10.0)


def lethal_near(costs: np.ndarray, xy, radius: float) -> int:
    xs, ys = SPEC.cell_centres()
    return int(((np.hypot(xs - xy[0], ys - xy[1]) <= radius) & (costs == LETHAL)).sum())


def test_without_social_layer_only_lidar_marks_and_their_inflation_remain():
    people, group = triad()
    layered = social_costmap(social=False)
    layered.update(LayerInputs(people, [group], scan_of(people)))
    assert set(layered.grids) == {"lidar", "inflation"}
    expected = layered.grids["lidar"].copy()
    InflationLayer(SPEC, InflationParams(), inscribed_radius=0.25).write(expected, SPEC.whole)
    np.testing.assert_array_equal(layered.master.costs, expected)
    assert layered.master.cost_at([group.interest_point])[0] < 240  # the o-space is not protected


def test_with_social_layer_the_group_zone_is_high_cost_in_the_master():
    people, group = triad()
    layered = social_costmap()
    layered.update(LayerInputs(people, [group], scan_of(people)))
    xs, ys = SPEC.cell_centres()
    inside = shapely.contains_xy(group_zone_polygon(group, people), xs, ys)
    assert (layered.master.costs[inside] >= 240).all()
    # between two members, where the baseline lets the robot through
    a, b = people[1], people[2]
    assert layered.master.cost_at([[(a.x + b.x) / 2, (a.y + b.y) / 2]])[0] >= 240


def test_a_moved_person_leaves_no_stale_marks_with_or_without_a_new_scan():
    old = [Person(1, 4.0, 0.0, np.pi)]
    new = [Person(1, 4.0, 1.5, np.pi)]
    for new_scan in (None, scan_of(new)):
        layered = social_costmap()
        layered.update(LayerInputs(old, [], scan_of(old)))
        assert lethal_near(layered.master.costs, (4.0, 0.0), 0.3) > 0
        layered.update(LayerInputs(new, [], new_scan))
        assert lethal_near(layered.master.costs, (4.0, 0.0), 0.3) == 0
        assert lethal_near(layered.grids["lidar"], (4.0, 1.5), 0.3) == 0  # the person is the social layer's, once
        assert lethal_near(layered.master.costs, (4.0, 1.5), 0.2) > 0
        assert layered.master.cost_at([[4.0, 0.0]])[0] < 50  # only the new position's fading personal space


def test_baseline_keeps_people_marks_where_no_new_beam_passes():
    old = [Person(1, 4.0, 0.0, np.pi)]
    layered = social_costmap(social=False)
    layered.update(LayerInputs(old, [], scan_of(old)))
    layered.update(LayerInputs([Person(1, 4.0, 1.5, np.pi)]))
    assert lethal_near(layered.master.costs, (4.0, 0.0), 0.3) > 0  # Nav2 behaviour without recognition


def test_something_left_at_a_person_old_position_is_kept_when_the_scan_sees_it():
    old = [Person(1, 4.0, 0.0, np.pi)]
    layered = social_costmap()
    layered.update(LayerInputs(old, [], scan_of(old)))
    pillar = simulate_scan((0.0, 0.0, 0.0), [CircleObstacle((4.0, 0.0), 0.2)], [], beams=720)
    layered.update(LayerInputs([Person(1, 4.0, 1.5, np.pi)], [], pillar))
    assert lethal_near(layered.master.costs, (4.0, 0.0), 0.3) > 0


def test_update_rejects_nan_people_duplicate_ids_and_a_sensor_off_the_map_before_changing_anything():
    layered = social_costmap()
    layered.update(LayerInputs([Person(1, 4.0, 0.0)], [], scan_of([Person(1, 4.0, 0.0)])))
    before = {"master": layered.master.costs.copy()} | {k: v.copy() for k, v in layered.grids.items()}
    with pytest.raises(ValueError, match="outside the costmap"):
        layered.update(LayerInputs([Person(1, 5.0, 0.0)], [], scan_of([], pose=(20.0, 0.0, 0.0))))
    after = {"master": layered.master.costs} | layered.grids
    for name, grid in before.items():
        np.testing.assert_array_equal(after[name], grid, err_msg=name)
    with pytest.raises(ValueError, match=r"members \[7\]"):  # the social layer refuses; the master waits
        layered.update(LayerInputs([Person(1, 5.0, 0.0)], [Group((1, 7), (5.0, 0.5), 0.0, np.zeros((0, 2)), 0.5)]))
    np.testing.assert_array_equal(layered.master.costs, before["master"])
    np.testing.assert_array_equal(layered.grids["social"], before["social"])
    assert layered.inputs.people == (Person(1, 4.0, 0.0),)
    with pytest.raises(ValueError, match="person 3"):
        layered.update(LayerInputs([Person(3, np.nan, 0.0)]))
    with pytest.raises(ValueError, match="twice"):
        layered.update(LayerInputs([Person(1, 0.0, 0.0), Person(1, 1.0, 0.0)]))


def test_unknown_space_stays_unknown_around_people_when_tracked():
    spec = GridSpec(0.05, 0.0, 0.0, 100, 100)
    layered = layered_costmap(spec, CostmapParams(obstacle=ObstacleParams(track_unknown_space=True)))
    layered.update(LayerInputs([Person(1, 2.5, 2.5, 0.0)]))  # no scan: everything unknown except the social costs
    costs = layered.master.costs
    assert costs[0, 0] == NO_INFORMATION
    assert costs[50, 50] == LETHAL and costs[50, 62] not in (0, NO_INFORMATION)


def test_static_map_walls_survive_and_lidar_adds_to_them(tmp_path):
    from costmap.mapfile import write_map
    from costmap.occupancy import OccupancyGrid
    from sid.scenario.build import build_costmap
    from sid.scenario.loader import scenario_from_dict

    spec = GridSpec(0.05, 0.0, 0.0, 100, 60)
    data = np.zeros(spec.shape, dtype=np.int8)
    data[50, :] = 100  # a wall along y = 2.525 in the static map
    data[56:, :5] = -1  # unknown, behind the static wall as seen from the robot
    write_map(tmp_path / "static.yaml", OccupancyGrid(spec, data))
    scenario = scenario_from_dict(
        {
            "static_map": "static.yaml",
            "obstacles": [{"type": "segment", "points": [[4.0, 0.5], [4.0, 2.0]]}],
            "robot": {"start": [1.0, 1.0], "goal": [4.5, 1.0]},
            "layers": {"obstacle": {"track_unknown_space": True}},
        },
        base_dir=tmp_path,
    )
    layered = build_costmap(scenario, social=False)
    assert list(layered.grids) == ["static", "lidar", "inflation"]
    master = layered.master.costs
    assert (master[50, :] == LETHAL).all()  # static wall, also where the LiDAR saw nothing
    assert (layered.grids["lidar"][10:40, 80] == LETHAL).any()  # the LiDAR-only wall at x = 4.0
    assert (master[56:, :5] == NO_INFORMATION).all()  # unknown in the static map, never seen
    scan = layered.inputs.scan
    assert scan is not None and scan.ranges[np.argmin(np.abs(scan.angles - np.pi / 2))] == pytest.approx(1.5, abs=0.05)
