"""Grid geometry and the Costmap2D record."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from costmap.grid import BORDER_TOLERANCE, LETHAL, NO_INFORMATION, Costmap2D, GridSpec, Window, disjoint, union

SPEC = GridSpec.from_size(0.05, (-1.0, -4.0), (10.0, 8.0))


def test_size_and_shape():
    assert (SPEC.width, SPEC.height) == (200, 160)
    assert SPEC.shape == (160, 200)
    assert SPEC.size_m == pytest.approx((10.0, 8.0))


@given(x=st.floats(-1.0, 8.99), y=st.floats(-4.0, 3.99))
def test_world_cell_round_trip_lands_within_half_a_cell(x, y):
    cell = SPEC.world_to_cell([[x, y]])
    assert SPEC.in_bounds(cell).all()
    centre = SPEC.cell_to_world(cell)[0]
    reach = SPEC.resolution * (0.5 + BORDER_TOLERANCE) + 1e-9  # a point just below a border: in the cell above
    assert abs(centre[0] - x) <= reach and abs(centre[1] - y) <= reach


def test_row_zero_is_lowest_y():
    assert tuple(SPEC.world_to_cell([[-1.0, -4.0]])[0]) == (0, 0)
    assert tuple(SPEC.world_to_cell([[8.99, 3.99]])[0]) == (159, 199)
    assert not SPEC.contains([[9.0, 0.0], [-1.01, 0.0]]).any()


@pytest.mark.parametrize("resolution", [0.0, -0.05, float("nan")])
def test_bad_resolution_is_named(resolution):
    with pytest.raises(ValueError, match="resolution"):
        GridSpec.from_size(resolution, (0, 0), (1, 1))


@pytest.mark.parametrize(
    ("width", "height", "message"),
    [
        (10.5, 10, r"map: width must be a whole number >= 1, got 10.5"),
        (True, True, r"map: width must be a whole number >= 1, got True"),
        (10, 0, r"map: height must be a whole number >= 1, got 0"),
        (10, "10", r"map: height must be a whole number >= 1, got '10'"),
    ],
)
def test_a_size_that_is_not_a_whole_number_of_cells_is_named(width, height, message):
    with pytest.raises(ValueError, match=message):
        GridSpec(0.1, 0, 0, width, height)
    spec = GridSpec(0.1, 0, 0, np.int64(10), 10.0)  # whole numbers of other types: stored as Python ints
    assert type(spec.width) is int and type(spec.height) is int and spec.shape == (10, 10)


def test_cost_at_reads_unknown_outside():
    costmap = Costmap2D.filled(SPEC)
    costmap.costs[80, 100] = LETHAL
    inside = SPEC.cell_to_world([[80, 100]])
    values = costmap.cost_at(np.vstack([inside, [[100.0, 100.0]]]))
    assert list(values) == [LETHAL, NO_INFORMATION]


def test_costmap_rejects_wrong_dtype():
    with pytest.raises(ValueError, match="uint8"):
        Costmap2D(SPEC, np.zeros(SPEC.shape, dtype=np.int16))


@given(
    st.lists(st.tuples(st.integers(0, 90), st.integers(1, 30), st.integers(0, 90), st.integers(1, 30)), max_size=20),
    st.sampled_from([0, 10, 200, 5000]),
)
def test_disjoint_windows_cover_the_given_ones_share_no_cell_and_merge_only_when_close(boxes, slack):
    given_windows = [Window(r, r + h, c, c + w) for r, h, c, w in boxes]
    out = disjoint([*given_windows, None], slack)
    covered = np.zeros((120, 120), dtype=int)
    for window in out:
        covered[window.slices] += 1
    assert covered.max(initial=0) <= 1  # no cell twice

    def inside(a: Window, b: Window) -> bool:
        return b.row0 <= a.row0 and a.row1 <= b.row1 and b.col0 <= a.col0 and a.col1 <= b.col1

    for window in given_windows:
        assert sum(inside(window, part) for part in out) == 1
    for part in out:  # each is the box of the given windows it holds
        assert union(*(w for w in given_windows if inside(w, part))) == part
    cells = [(w.row1 - w.row0) * (w.col1 - w.col0) for w in out]
    for (i, a), (j, b) in itertools.combinations(enumerate(out), 2):  # none left that should merge
        u = union(a, b)
        assert (u.row1 - u.row0) * (u.col1 - u.col0) - cells[i] - cells[j] > slack


def test_disjoint_keeps_far_changes_apart_and_merges_near_ones():
    a, b = Window(0, 10, 0, 10), Window(0, 10, 300, 310)
    assert disjoint([a, b], slack=2899) == [a, b]  # their box would add 2,900 cells
    assert disjoint([a, b], slack=2900) == [union(a, b)]
    assert disjoint([a, Window(5, 20, 5, 20), None]) == [Window(0, 20, 0, 20)]  # overlapping: always merged
    assert disjoint([]) == [] and disjoint([None]) == []


def test_a_world_box_covers_the_cells_it_overlaps_clipped_to_the_grid():
    spec = GridSpec.from_size(0.05, (-2.0, -5.0), (12.0, 10.0))
    rng = np.random.default_rng(0)
    for x0, y0, w, h in rng.uniform([-3.0, -6.0, -0.5, -0.5], [11.0, 6.0, 4.0, 4.0], (2000, 4)):
        for box in ((x0, y0, x0 + w, y0 + h), (round(x0, 2), round(y0, 2), round(x0 + w, 1), round(y0 + h, 1))):
            col0, col1 = (math.floor((box[k] + 2.0) / 0.05 + BORDER_TOLERANCE) + k // 2 for k in (0, 2))
            row0, row1 = (math.floor((box[k] + 5.0) / 0.05 + BORDER_TOLERANCE) + k // 2 for k in (1, 3))
            assert spec.window(box[:2], box[2:]) == Window(row0, row1, col0, col1).clipped(spec)
    for box in ((np.nan, 0.0, 1.0, 1.0), (0.0, 0.0, np.inf, 1.0), (-np.inf, 0.0, 1.0, 1.0), (20.0, 0.0, 21.0, 1.0)):
        assert spec.window(box[:2], box[2:]) is None


def test_windows_union_grow_and_clip():
    a, b = Window(2, 5, 3, 4), Window(4, 9, 0, 2)
    assert a.union(b) == union(None, a, None, b) == Window(2, 9, 0, 4)
    assert union(None, None) is None and a.union(None) == a
    assert Window(1, 3, 1, 3).grown(2, SPEC) == Window(0, 5, 0, 5)
    assert SPEC.whole.grown(3, SPEC) == SPEC.whole == Window(0, 160, 0, 200)
    assert Window(-5, 2, 190, 300).clipped(SPEC) == Window(0, 2, 190, 200)
    assert Window(-5, 0, 0, 3).clipped(SPEC) is None
    assert SPEC.window((20.0, 0.0), (21.0, 1.0)) is None
    assert SPEC.window((np.nan, 0.0), (1.0, 1.0)) is None and SPEC.window((0.0, 0.0), (np.inf, 1.0)) is None
    costs = np.zeros(SPEC.shape)
    costs[Window(1, 3, 4, 7).slices] = 1
    assert costs.sum() == 6


@pytest.mark.parametrize("origin", [(0.0, 0.0), (1000.0, -500.0), (-12345.65, 7890.1), (1e6, -1e6)])
def test_a_point_on_a_cell_border_is_in_the_cell_above_whatever_the_origin(origin):
    # 4.6 / 0.05 divides to 91.99999999999999: the box of a scene at y = 4.6 m started a row low, and the same scene
    # moved with its origin gave other cells (a helper's probe: 324 cells of a costmap).
    spec = GridSpec.from_size(0.05, origin, (10.0, 10.0))
    borders = np.array([[k * 0.05, k * 0.05] for k in range(201)]) + origin
    cells = spec.world_to_cell(borders)
    assert (cells == np.arange(201)[:, None]).all()
    inner = spec.world_to_cell(borders[1:] - 1e-7)  # a tenth of a micrometre below: the cell below
    assert (inner == np.arange(200)[:, None]).all()
    assert spec.contains(borders[:200]).all() and not spec.contains(borders[200:]).any()
    window = spec.window((origin[0] + 2.0, origin[1] + 4.6), (origin[0] + 3.0, origin[1] + 5.0))
    assert window == Window(92, 101, 40, 61)
