"""The social layer: group zones, personal space and zone fall-off against the float64 formulas, batched painting
against one by one, clipping; the zones held to a plain reference (shapely's distance from each cell centre)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, MultiPoint, Point

from costmap.grid import FREE_SPACE, INSCRIBED, LETHAL, NO_INFORMATION, Costmap2D, GridSpec
from costmap.layer import LayerInputs
from costmap.layers.social import (
    GROUPS,
    PEOPLE,
    SocialLayer,
    SocialParams,
    _distance_to_hull,
    _hull_ring,
    group_zone_polygon,
    paint_bodies,
    paint_body,
    paint_group,
    paint_groups,
    paint_people,
    paint_person,
    zone_hull,
)
from sid.perception.group import Group
from sid.perception.people import Person
from tests.costmap.scenes import triad

SPEC = GridSpec.from_size(0.05, (-1.0, -4.0), (10.0, 8.0))
REFERENCE_SPEC = GridSpec.from_size(0.05, (-2.0, -2.0), (12.0, 10.0))
PARAMS = SocialParams()


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


@pytest.mark.parametrize(
    ("members", "zone", "message"),
    [
        ((), np.zeros((0, 2)), r"group \(\): no member and no zone vertex, so no zone to draw"),
        (
            (1,),
            np.array([1.0, 1.0, 2.0, 2.0]),
            r"group \(1,\): zone must be \(K, 2\) vertices \(x, y\), got shape \(4,\)",
        ),
        ((1,), np.zeros((2, 3)), r"zone must be \(K, 2\) vertices \(x, y\), got shape \(2, 3\)"),
    ],
)
def test_a_group_without_a_zone_to_draw_is_named_before_the_layer_changes(members, zone, message) -> None:
    people = [Person(1, 1.0, 1.0, 0.0)]
    layer = SocialLayer(SPEC)
    layer.update(LayerInputs({PEOPLE: people}), SPEC.whole)
    before = layer.costs.copy()
    with pytest.raises(ValueError, match=message):
        layer.update(LayerInputs({PEOPLE: people, GROUPS: (Group(members, (1.0, 1.0), 0.0, zone, 0.0),)}), SPEC.whole)
    np.testing.assert_array_equal(layer.costs, before)


def test_every_cell_inside_the_group_zone_costs_at_least_group_cost():
    people, group = triad()
    params = SocialParams()
    layer = SocialLayer(SPEC, params)
    layer.update(LayerInputs({PEOPLE: people, GROUPS: [group]}), None)
    xs, ys = SPEC.cell_centres()
    inside = shapely.contains_xy(group_zone_polygon(group, people, params.group_margin), xs, ys)
    assert inside.sum() > 300
    assert (layer.costs[inside] >= params.group_cost).all()
    assert layer.costs.max() == LETHAL  # bodies only
    assert not np.isin(layer.costs, [INSCRIBED, NO_INFORMATION]).any()
    assert (layer.costs[layer.costs != LETHAL] <= 252).all()


def test_personal_space_is_larger_in_front_and_circular_without_orientation():
    layer = SocialLayer(SPEC, SocialParams())
    layer.update(LayerInputs({PEOPLE: [Person(1, 2.0, 0.0, 0.0), Person(2, 6.0, 0.0, None)]}), None)
    costmap = Costmap2D(SPEC, layer.costs)
    front, back = costmap.cost_at([[2.8, 0.0], [1.2, 0.0]])
    assert front > back > 0
    # Points inside cells mirrored about the person (a point on a cell border is in the cell above or to the right)
    left, right = costmap.cost_at([[2.0, 0.61], [2.0, -0.61]])
    assert left == right
    around = costmap.cost_at([[6.61, 0.0], [5.39, 0.0], [6.0, 0.61], [6.0, -0.61]])
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
    beyond = [Person(1, 9.3, 0.0, np.pi)]  # 0.3 m beyond the right edge, facing into the map
    layer.update(LayerInputs({PEOPLE: beyond}), None)
    assert layer.costs[:, -1].max() > 0
    assert not (layer.costs == LETHAL).any()  # the body itself is outside


def reference_zone_costs(hulls, spec: GridSpec, params: SocialParams) -> np.ndarray:
    """Per cell, the highest zone cost of ``hulls`` (world frame, m): group_cost within group_margin of a hull,
    falling off as group_cost exp(-(d - margin)^2 / (2 group_sigma^2)) beyond, floored to a whole cost."""
    xs, ys = spec.cell_axes()
    centres = shapely.points(
        np.broadcast_to(xs, (spec.height, spec.width)), np.broadcast_to(ys, (spec.height, spec.width))
    )
    best = np.zeros(spec.shape)
    for hull in hulls:
        beyond = np.maximum(shapely.distance(hull, centres) - params.group_margin, 0.0)
        best = np.maximum(best, np.floor(params.group_cost * np.exp(-(beyond**2) / (2 * params.group_sigma**2))))
    return best


def random_hulls(rng: np.random.Generator) -> list:
    """Convex zones of 3-8 points (most groups), segments (a pair in line) and points (a face-to-face pair)."""
    hulls = []
    for _ in range(int(rng.integers(1, 7))):
        centre = rng.uniform(0, 8, 2)
        kind = rng.choice(["polygon", "polygon", "segment", "point"])
        if kind == "polygon":
            hull = MultiPoint(centre + rng.normal(0, 0.4, (int(rng.integers(3, 9)), 2))).convex_hull
        elif kind == "segment":
            hull = LineString([centre, centre + rng.normal(0, 0.4, 2)])
        else:
            hull = Point(centre)
        hulls.append(hull)
    return hulls


@pytest.mark.parametrize("seed", range(12))
def test_zones_cost_what_the_distance_to_them_says(seed: int) -> None:
    rng = np.random.default_rng(seed)
    hulls = random_hulls(rng)
    costs = np.full(REFERENCE_SPEC.shape, FREE_SPACE, dtype=np.uint8)
    paint_groups(costs, REFERENCE_SPEC, hulls, PARAMS)
    expected = reference_zone_costs(hulls, REFERENCE_SPEC, PARAMS)
    difference = np.abs(costs.astype(int) - expected.astype(int))
    # float32 arithmetic in the layer, float64 here: a cost floored the other side of a whole number differs by 1
    assert difference.max() <= 1
    assert np.count_nonzero(difference) <= 0.002 * np.count_nonzero(expected)
    assert np.count_nonzero(costs == PARAMS.group_cost) == pytest.approx(
        np.count_nonzero(expected == PARAMS.group_cost), rel=0.01
    )


@pytest.mark.parametrize("seed", range(12))
def test_the_distance_to_a_zone_is_shapelys(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    for hull in random_hulls(rng):
        window = REFERENCE_SPEC.window(tuple(hull.bounds[:2] - np.array(1.5)), tuple(hull.bounds[2:] + np.array(1.5)))
        ring, polygon = _hull_ring(hull)
        distance = _distance_to_hull(REFERENCE_SPEC, window, ring, polygon)
        xs, ys = REFERENCE_SPEC.cell_axes(window)
        centres = shapely.points(np.broadcast_to(xs, distance.shape), np.broadcast_to(ys, distance.shape))
        np.testing.assert_allclose(distance, shapely.distance(hull, centres), atol=2e-5)  # float32 in the layer


@pytest.mark.parametrize(
    "params", [SocialParams(), SocialParams(sigma_rear=0.05, sigma_side=0.05), SocialParams(amplitude=0.0)]
)
def test_the_windows_an_update_reports_hold_every_cell_it_painted_and_the_next_update_clears_them(params) -> None:
    # Bodies within their personal space add no window of their own; bodies wider than it (a narrow space, none at
    # amplitude 0) keep theirs, so the next update still clears them.
    rng = np.random.default_rng(5)
    layer = SocialLayer(SPEC, params, body_radius=0.3)
    people = [Person(i, *map(float, rng.uniform((0, -3, -4), (8, 3, 4)))) for i in range(9)]
    pair = Group((0, 1), (4.0, 0.0), 0.0, np.empty((0, 2)), 0.5)
    windows = layer.update_windows(LayerInputs({PEOPLE: people, GROUPS: [pair]}), [])
    covered = np.zeros(SPEC.shape, dtype=bool)
    for window in windows:
        assert not covered[window.slices].any(), "the windows share no cell"
        covered[window.slices] = True
    assert (layer.costs == LETHAL).any() and not (layer.costs[~covered] != FREE_SPACE).any()
    layer.update_windows(LayerInputs({PEOPLE: []}), [])
    assert not layer.costs.any()
