"""Combination methods: Nav2's rules, in place, on every pair of uint8 values and on windows."""

from __future__ import annotations

import numpy as np
import pytest

from costmap.combine import combine
from costmap.grid import FREE_SPACE, INSCRIBED, NO_INFORMATION


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
    known = np.array([0, 10, 253, 254], dtype=np.uint8)
    combine(known, np.full(4, NO_INFORMATION, dtype=np.uint8), "max_nonzero")  # the plain-max path
    assert known.tolist() == [0, 10, 253, 254]  # nor does an unknown layer cell turn a known master cell unknown


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
        no_opinion = (layer == NO_INFORMATION) | ((layer == FREE_SPACE) & (method == "max_nonzero"))
        expected = np.where(no_opinion, master, np.where(unknown, layer, larger))
    windows = [(slice(None), slice(None)), (slice(0, 255), slice(0, 255)), (slice(3, 90), slice(7, 255))]
    for rows, cols in [*windows, (slice(0, 0), slice(None)), (slice(None, None, 3), slice(None, None, -2))]:
        out = master.copy()
        combine(out[rows, cols], layer[rows, cols], method)
        np.testing.assert_array_equal(out[rows, cols], expected[rows, cols])
        out[rows, cols] = master[rows, cols]
        np.testing.assert_array_equal(out, master)  # nothing outside the window
