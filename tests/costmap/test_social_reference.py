"""Group zones painted by the social layer's two paths (the batched polygons, and points and segments one by one) held
to a plain reference: shapely's distance from each cell centre to the zone, through the zone cost's formula."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, MultiPoint, Point

from costmap.grid import FREE_SPACE, GridSpec
from costmap.layers.social import SocialParams, _distance_to_hull, _hull_ring, paint_groups

SPEC = GridSpec.from_size(0.05, (-2.0, -2.0), (12.0, 10.0))
PARAMS = SocialParams()


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
    costs = np.full(SPEC.shape, FREE_SPACE, dtype=np.uint8)
    paint_groups(costs, SPEC, hulls, PARAMS)
    expected = reference_zone_costs(hulls, SPEC, PARAMS)
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
        window = SPEC.window(tuple(hull.bounds[:2] - np.array(1.5)), tuple(hull.bounds[2:] + np.array(1.5)))
        ring, polygon = _hull_ring(hull)
        distance = _distance_to_hull(SPEC, window, ring, polygon)
        xs, ys = SPEC.cell_axes(window)
        centres = shapely.points(np.broadcast_to(xs, distance.shape), np.broadcast_to(ys, distance.shape))
        np.testing.assert_allclose(distance, shapely.distance(hull, centres), atol=2e-5)  # float32 in the layer
