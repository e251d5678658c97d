"""Social-navigation metrics on hand-made paths, people and groups (exact expected values)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from shapely.geometry import LineString

from costmap.grid import LETHAL, Costmap2D, GridSpec
from costmap.layers.social import group_zone_polygon
from planner.facade import PlanResult
from sid.experiments.path_metrics import (
    FIXED_KEYS,
    heading_change,
    min_distance_to_points,
    path_length,
    path_metrics,
    result_metrics,
)
from sid.perception.group import Group
from sid.perception.people import Person

TRIO = [Person(1, 4.0, 0.9, -math.pi / 2), Person(2, 3.2, -0.5, math.pi / 6), Person(3, 4.8, -0.5, 5 * math.pi / 6)]


def trio_group() -> Group:
    zone = np.array([[3.8, -0.1], [4.2, -0.1], [4.0, 0.25]])
    return Group((1, 2, 3), (4.0, 0.0), 0.07, zone, 0.9)


def test_length_heading_and_exact_distance():
    path = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 4.0]])
    assert path_length(path) == pytest.approx(7.0)
    assert heading_change(path) == pytest.approx(math.pi / 2)
    assert heading_change(np.array([[0, 0], [1, 0], [1, 0], [2, 0]])) == 0.0  # zero-length segment skipped
    assert min_distance_to_points(path, [[1.5, 0.7], [10.0, 10.0]]) == pytest.approx(0.7)
    assert min_distance_to_points(path, np.zeros((0, 2))) == math.inf


def test_path_through_the_group_intrudes_and_crosses():
    group = trio_group()
    path = np.array([[0.0, 0.0], [8.0, 0.0]])
    m = path_metrics(path, TRIO, [group])
    chord = group_zone_polygon(group, TRIO).intersection(LineString(path)).length
    assert m["ospace_intrusion_m"] == pytest.approx(chord) and chord > 1.5
    assert m["crosses_group"] is True
    assert m["min_person_distance_m"] == pytest.approx(0.5)
    assert m["length_ratio"] == pytest.approx(1.0)


def test_path_around_the_group_stays_out():
    path = np.array([[0.0, 0.0], [2.0, 0.0], [4.0, 3.0], [6.0, 0.0], [8.0, 0.0]])
    m = path_metrics(path, TRIO, [trio_group()])
    assert m["ospace_intrusion_m"] == 0.0 and m["crosses_group"] is False
    assert m["goal_in_group_zone"] is False


def test_every_group_counts_not_only_the_first():
    """Two groups; the paths stay far from the trio (the first) and cross, or end in, the pair's zone (the second)."""
    pair_people = [Person(4, 4.0, 5.6, -math.pi / 2), Person(5, 4.0, 4.4, math.pi / 2)]
    pair = Group((4, 5), (4.0, 5.0), 0.0, np.array([[4.0, 5.0]]), 0.6)
    people, groups = TRIO + pair_people, [trio_group(), pair]
    zone = group_zone_polygon(pair, people)
    for path, crosses, ends_inside in (
        (np.array([[0.0, 5.0], [8.0, 5.0]]), True, False),  # between the two members
        (np.array([[0.0, 5.0], [3.9, 5.0]]), False, True),  # stops short of them, inside the zone
    ):
        assert group_zone_polygon(groups[0], people).distance(LineString(path)) > 2.0
        m = path_metrics(path, people, groups)
        chord = zone.intersection(LineString(path)).length
        assert m["ospace_intrusion_m"] == pytest.approx(chord) and chord > 0.15
        assert m["crosses_group"] is crosses
        assert m["goal_in_group_zone"] is ends_inside


def test_bands_of_a_path_at_constant_distance():
    person = Person(7, 0.0, 0.0, 0.0)
    for radius, band in ((0.3, "intimate"), (1.0, "personal"), (2.0, "social")):
        angles = np.linspace(0, math.pi, 200)
        arc = radius * np.stack([np.cos(angles), np.sin(angles)], axis=1)
        m = path_metrics(arc, [person], [])
        assert m["band_fractions"][band] == 1.0
        assert m["personal_space_fraction"] == (1.0 if radius < 1.2 else 0.0)
        assert m["min_person_distance_m"] == pytest.approx(radius, abs=1e-3)


def test_cost_integral_and_lethal_samples_on_a_costmap():
    spec = GridSpec.from_size(0.1, (0.0, 0.0), (4.0, 2.0))
    costs = np.zeros(spec.shape, np.uint8)
    costs[:, 10:20] = 126  # x in [1, 2): half of the highest graded cost
    costs[0, 35] = LETHAL
    m = path_metrics(np.array([[0.05, 1.0], [3.95, 1.0]]), [], [], Costmap2D(spec, costs))
    assert m["cost_integral"] == pytest.approx(0.5, abs=0.02)
    assert m["lethal_samples"] == 0 and m["min_person_distance_m"] is None
    m = path_metrics(np.array([[3.55, 0.5], [3.55, 0.01]]), [], [], Costmap2D(spec, costs))
    assert m["lethal_samples"] > 0


def test_result_metrics_keep_the_fixed_keys_and_serialise():
    ok = PlanResult("grid", True, np.array([[0.0, 0.0], [8.0, 0.0]]), 8.0, 8.0, 0.1, 0.05, 8.2, 0, None, "ok")
    failed = PlanResult("bitstar", False, np.zeros((0, 2)), math.inf, 0.0, 0.5, 0.5, math.inf, 900, 3, "no path")
    for result in (ok, failed):
        m = result_metrics(result, TRIO, [trio_group()])
        assert set(FIXED_KEYS) <= set(m)
        json.dumps(m, allow_nan=False)
    m = result_metrics(failed, TRIO, [trio_group()])
    assert m["success"] is False and m["ospace_intrusion_m"] is None and m["raw_cost"] is None


def test_bad_path_is_refused():
    with pytest.raises(ValueError, match="non-empty path of finite"):
        path_metrics(np.array([[0.0, math.nan]]), TRIO, [])
