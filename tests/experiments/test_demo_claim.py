"""The project's claim as a test: with group recognition the default planner stays out of every group zone; without
it, it cuts through a conversation it could pass between. Fixed seeds and iteration caps, so runs are exact."""

from __future__ import annotations

import copy

import pytest
from shapely.geometry import Point

from costmap.layers.social import group_zone_polygon
from sid.experiments.demo import DEMO_SCENARIO, _circle, compare_with_without, demo_scenario, goal_zone_warning
from sid.scenario.loader import scenario_from_dict
from sid.synthetic.layouts import LAYOUTS

BUDGET = dict(time_limit=30.0, seed=1, max_iterations=5000)  # the cap, not the time, ends these runs

# The paper's layouts S1-S5 (sid.synthetic.layouts) and wider conversations (o-space radius within the detector's
# spread threshold); the robot could squeeze between the members of the pair and of the triangle.
LAYOUT_CASES = {name: (spec.angles_deg, spec.radius) for name, spec in LAYOUTS.items()} | {
    "pair 1.6 m apart": ((90.0, -90.0), 0.8),
    "triangle 1.56 m sides": ((90.0, 210.0, 330.0), 0.9),
    "semicircle of 4": ((-67.5, -22.5, 22.5, 67.5), 0.95),
    "circle of 5": ((0.0, 72.0, 144.0, 216.0, 288.0), 0.95),
}


def scenario_with(angles: tuple[float, ...], radius: float, turn: float = 0.0):
    """The demo corridor and task with the conversation replaced by people on a circle around (4.5, 0)."""
    data = copy.deepcopy(DEMO_SCENARIO)
    data["people"] = _circle(tuple(range(1, len(angles) + 1)), (4.5, 0.0), radius, tuple(a + turn for a in angles))
    return scenario_from_dict(data)


def test_builtin_demo_goes_through_without_and_around_with_recognition():
    comparison = compare_with_without(demo_scenario(), **BUDGET)
    without, with_ = comparison.metrics["without"], comparison.metrics["with"]
    assert [g.members for g in comparison.groups] == [(1, 2, 3)]  # the lone person 4 is not in the group
    assert without["success"] and with_["success"]
    assert without["ospace_intrusion_m"] > 1.0 and without["crosses_group"] is True
    assert with_["ospace_intrusion_m"] == 0.0 and with_["crosses_group"] is False
    assert with_["min_person_distance_m"] > without["min_person_distance_m"]
    assert with_["path_length_m"] < 1.2 * without["path_length_m"]  # a modest detour
    assert with_["lethal_samples"] == 0 and without["lethal_samples"] == 0


@pytest.mark.parametrize("turn", [0.0, 90.0])
@pytest.mark.parametrize("name", list(LAYOUT_CASES))
def test_with_recognition_never_enters_a_group_zone(name, turn):
    angles, radius = LAYOUT_CASES[name]
    comparison = compare_with_without(scenario_with(angles, radius, turn), **BUDGET)
    found = [g.members for g in comparison.groups]
    assert len(found) == 1 and len(found[0]) == len(angles), (
        f"sid.perception.groups.detect_groups found {found}: no test"
    )
    with_ = comparison.metrics["with"]
    assert with_["success"], with_["message"]
    assert with_["ospace_intrusion_m"] == 0.0 and with_["crosses_group"] is False


@pytest.mark.parametrize("name", ["pair 1.6 m apart", "triangle 1.56 m sides"])
def test_without_recognition_wide_conversations_are_crossed(name):
    angles, radius = LAYOUT_CASES[name]
    comparison = compare_with_without(scenario_with(angles, radius), **BUDGET)
    assert comparison.metrics["without"]["ospace_intrusion_m"] > 0.0
    assert comparison.metrics["without"]["crosses_group"] is True


def test_goal_inside_a_group_zone_is_planned_and_reported():
    data = copy.deepcopy(DEMO_SCENARIO)
    data["robot"]["goal"] = [4.5, 0.0, 0.0]  # the conversation's o-space centre
    scenario = scenario_from_dict(data)
    comparison = compare_with_without(scenario, **BUDGET)
    warning = goal_zone_warning(scenario, comparison.groups)
    assert warning is not None and "inside the interaction zone of group (1, 2, 3)" in warning
    with_ = comparison.metrics["with"]
    assert with_["success"] and with_["goal_in_group_zone"] is True
    zone = group_zone_polygon(comparison.groups[0], scenario.people)
    depth = zone.exterior.distance(Point(4.5, 0.0))  # the shortest way in from the zone's edge
    assert 0.0 < with_["ospace_intrusion_m"] < depth + 0.5
    assert goal_zone_warning(demo_scenario(), comparison.groups) is None
