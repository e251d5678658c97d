"""The project's claim as a test: with group recognition the default planner stays out of every group zone; without
it, it cuts through a conversation it could pass between. Fixed seeds and iteration caps, so runs are exact."""

from __future__ import annotations

import copy

import pytest
from shapely.geometry import Point

from costmap.layers.social import group_zone_polygon
from planner.facade import DEFAULT_PLANNER
from sid.experiments.demo import DEMO_ITERATIONS, DEMO_SCENARIO, _circle, run_demo
from sid.experiments.harness import compare_with_without, prepare
from sid.scenario.loader import scenario_from_dict
from sid.synthetic.layouts import LAYOUTS

BUDGET = dict(planner=DEFAULT_PLANNER, time_limit=30.0, seed=1, max_iterations=5000)  # the cap ends these runs

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


def test_the_demo_claim_at_its_defaults(tmp_path):
    """``sid demo`` as the README reports it: its seed and iteration cap; only the time guard is raised, so that a
    loaded machine cannot end the runs before the cap."""
    comparison = run_demo(tmp_path, time_limit=120.0)
    assert [g.members for g in comparison.task.groups] == [(1, 2, 3)]  # the lone person 4 is not in the group
    assert all(run.result.iterations == DEMO_ITERATIONS for run in comparison.runs.values())  # the cap ended both
    without, with_ = comparison.metrics["without"], comparison.metrics["with"]
    assert round(without["path_length_m"], 2) == 9.07 and round(with_["path_length_m"], 2) == 9.89
    assert round(without["ospace_intrusion_m"], 2) == 1.43 and with_["ospace_intrusion_m"] == 0.0
    assert without["crosses_group"] is True and with_["crosses_group"] is False
    assert round(without["min_person_distance_m"], 2) == 0.73 and round(with_["min_person_distance_m"], 2) == 1.26
    assert without["lethal_samples"] == 0 and with_["lethal_samples"] == 0


@pytest.mark.parametrize("turn", [0.0, 90.0])
@pytest.mark.parametrize("name", list(LAYOUT_CASES))
def test_with_recognition_never_enters_a_group_zone(name, turn):
    angles, radius = LAYOUT_CASES[name]
    comparison = compare_with_without(prepare(scenario_with(angles, radius, turn)), **BUDGET)
    found = [g.members for g in comparison.task.groups]
    assert len(found) == 1 and len(found[0]) == len(angles), (
        f"sid.perception.groups.detect_groups found {found}: no test"
    )
    with_ = comparison.metrics["with"]
    assert with_["success"], with_["message"]
    assert with_["ospace_intrusion_m"] == 0.0 and with_["crosses_group"] is False


@pytest.mark.parametrize("name", ["pair 1.6 m apart", "triangle 1.56 m sides"])
def test_without_recognition_wide_conversations_are_crossed(name):
    angles, radius = LAYOUT_CASES[name]
    comparison = compare_with_without(prepare(scenario_with(angles, radius)), **BUDGET)
    assert comparison.metrics["without"]["ospace_intrusion_m"] > 0.0
    assert comparison.metrics["without"]["crosses_group"] is True


def test_goal_inside_a_group_zone_is_planned_and_reported():
    data = copy.deepcopy(DEMO_SCENARIO)
    data["robot"]["goal"] = [4.5, 0.0, 0.0]  # the conversation's o-space centre
    task = prepare(scenario_from_dict(data))
    with_ = compare_with_without(task, **BUDGET).metrics["with"]
    assert with_["success"] and with_["goal_in_group_zone"] is True
    zone = group_zone_polygon(task.groups[0], task.scenario.people)
    depth = zone.exterior.distance(Point(4.5, 0.0))  # the shortest way in from the zone's edge
    assert 0.0 < with_["ospace_intrusion_m"] < depth + 0.5
