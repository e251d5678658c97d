"""Grid geometry and the Costmap2D record."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from costmap.grid import LETHAL, NO_INFORMATION, Costmap2D, GridSpec

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
    assert abs(centre[0] - x) <= SPEC.resolution / 2 + 1e-9
    assert abs(centre[1] - y) <= SPEC.resolution / 2 + 1e-9


def test_row_zero_is_lowest_y():
    assert tuple(SPEC.world_to_cell([[-1.0, -4.0]])[0]) == (0, 0)
    assert tuple(SPEC.world_to_cell([[8.99, 3.99]])[0]) == (159, 199)
    assert not SPEC.contains([[9.0, 0.0], [-1.01, 0.0]]).any()


@pytest.mark.parametrize("resolution", [0.0, -0.05, float("nan")])
def test_bad_resolution_is_named(resolution):
    with pytest.raises(ValueError, match="resolution"):
        GridSpec.from_size(resolution, (0, 0), (1, 1))


def test_cost_at_reads_unknown_outside():
    costmap = Costmap2D.filled(SPEC)
    costmap.costs[80, 100] = LETHAL
    inside = SPEC.cell_to_world([[80, 100]])
    values = costmap.cost_at(np.vstack([inside, [[100.0, 100.0]]]))
    assert list(values) == [LETHAL, NO_INFORMATION]


def test_costmap_rejects_wrong_dtype():
    with pytest.raises(ValueError, match="uint8"):
        Costmap2D(SPEC, np.zeros(SPEC.shape, dtype=np.int16))
