"""The inflation layer: Nav2's formula and reach, its unknown rule, incremental recomputation, windows."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from costmap.grid import FREE_SPACE, INSCRIBED, LETHAL, NO_INFORMATION, GridSpec, Window
from costmap.layers.inflation import (
    SQUARED_DISTANCE_EXACT,
    InflationLayer,
    InflationParams,
    squared_distance_to_lethal_cells,
)
from costmap.plugins import CostmapParams, LayerInstance, layered_costmap

SPEC = GridSpec.from_size(0.05, (-1.0, -4.0), (10.0, 8.0))


def nav2_cost(d_m: float, inscribed: float, k: float) -> int:
    """Nav2's InflationLayer::computeCost written out by hand for one distance."""
    if d_m == 0:
        return 254
    if d_m <= inscribed:
        return 253
    return int(252 * np.exp(-k * (d_m - inscribed)))


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


def test_an_inflation_radius_beyond_the_maps_diagonal_is_named_on_every_path():
    spec = GridSpec(0.05, 0.0, 0.0, 60, 80)  # 3 x 4 m: a diagonal of 5 m
    assert InflationLayer(spec, InflationParams(inflation_radius=5.0), 0.25).cell_radius == 100
    with pytest.raises(ValueError, match=r"inflation layer: inflation_radius: 5.01 m is more than the map's diagonal"):
        InflationLayer(spec, InflationParams(inflation_radius=5.01), 0.25)  # the table of (R cells)^2 never made
    params = CostmapParams(
        plugins=("lidar", "wide"), instances={"wide": LayerInstance("inflation", InflationParams(50))}
    )
    with pytest.raises(ValueError, match=r"inflation_radius: 50 m is more than the map's diagonal \(5 m\)"):
        layered_costmap(spec, params)


@pytest.mark.parametrize(("shape", "density"), [((120, 90), 0.01), ((300, 400), 0.001), ((1400, 1400), 0.0)])
def test_squared_distances_are_scipys_exact_ones(shape, density):
    rng = np.random.default_rng(0)
    lethal = rng.random(shape) < density
    lethal[0, 0] = True  # on the largest grid: squared distances up to 2 x 1399^2, near SQUARED_DISTANCE_EXACT
    exact = np.rint(ndimage.distance_transform_edt(~lethal) ** 2)
    assert exact.max() < SQUARED_DISTANCE_EXACT
    np.testing.assert_array_equal(squared_distance_to_lethal_cells(lethal, np.inf), exact)
    np.testing.assert_array_equal(squared_distance_to_lethal_cells(lethal, 50.0), np.minimum(exact, 50.0))


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


def test_inflation_written_window_by_window_reaches_across_their_edges():
    # A lethal cell that changes near the edge of one window is found by the first window whose reach holds it; the
    # cells within reach of it in the next window must be recomputed then, though that window finds no change.
    master = np.zeros(SPEC.shape, dtype=np.uint8)
    master[60:64, 100:103] = LETHAL
    first, second = Window(40, 80, 60, 96), Window(40, 80, 96, 140)  # the lethal cells lie in the second
    for order in ((first, second), (second, first)):
        layer = InflationLayer(SPEC, InflationParams(), inscribed_radius=0.25)
        full = master.copy()
        InflationLayer(SPEC, InflationParams(), inscribed_radius=0.25).write(full, SPEC.whole)
        part = master.copy()
        for window in order:
            layer.write(part, window)
        for window in order:
            np.testing.assert_array_equal(part[window.slices], full[window.slices])


def test_inflation_over_a_window_reads_the_lethal_cells_within_reach_of_it():
    master = np.zeros(SPEC.shape, dtype=np.uint8)
    master[50, 50] = master[75, 120] = LETHAL  # outside the window, within reach of it
    layer = InflationLayer(SPEC, InflationParams(), inscribed_radius=0.25)
    full = master.copy()
    layer.write(full, SPEC.whole)
    window = Window(53, 70, 40, 130)
    part = master.copy()
    layer.write(part, window)
    np.testing.assert_array_equal(part[window.slices], full[window.slices])
    assert part[window.slices].any()
    part[window.slices] = master[window.slices]
    np.testing.assert_array_equal(part, master)  # nothing written outside the window
