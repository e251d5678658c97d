"""The with/without harness: what a run measures, the run matrix, run records and the one summary."""

from __future__ import annotations

import copy
import itertools

import pytest

from planner.problem import NoPathError, PlanningError, WalledOffError
from sid.documents import InputWarning
from sid.experiments.demo import DEMO_SCENARIO, demo_scenario
from sid.experiments.harness import (
    compare_with_without,
    people_at_ends,
    people_walling_off,
    prepare,
    run_matrix,
    summarise,
    zone_warnings,
)
from sid.scenario.loader import scenario_from_dict


@pytest.fixture(scope="module")
def task():
    return prepare(demo_scenario())


def test_both_modes_are_measured_on_the_social_costmap_against_the_detected_groups(task):
    assert [g.members for g in task.groups] == [(1, 2, 3)]  # the lone person 4 is not in the group
    comparison = compare_with_without(task, "grid", 1.0, reference=True)
    without, with_ = comparison.runs["without"], comparison.runs["with"]
    # Without the social layer the robot does not know the group, but its path is still measured against it.
    assert without.metrics["crosses_group"] is True and without.metrics["ospace_intrusion_m"] > 1.0
    assert without.metrics["cost_integral"] > with_.metrics["cost_integral"]  # both on the social costs
    assert without.cost_ratio == with_.cost_ratio == 1.0  # the grid planner is its own reference
    assert without.detour is None and with_.detour == pytest.approx(
        with_.metrics["path_length_m"] / without.metrics["path_length_m"]
    )
    record = with_.record()
    assert record["social_layer"] is True and record["planner"] == "grid" and record["scenario"] == task.scenario.name
    assert record["detour"] == with_.detour and record["path_length_m"] == with_.metrics["path_length_m"]


def test_labels_go_into_records_and_win_over_metrics(task):
    labelled = prepare(task.scenario, labels={"layout": "T3", "seed": 7})
    run = compare_with_without(labelled, "rrtconnect", 5.0, seed=2, modes=("with",)).runs["with"]
    assert run.metrics["seed"] == 2  # the planner's seed
    assert run.record()["seed"] == 7 and run.record()["layout"] == "T3"  # the task's


def test_run_matrix_plans_grid_once_and_counts_progress(task):
    calls: list[tuple[int, int]] = []
    runs = run_matrix(
        [task], ["grid", "rrtconnect"], runs=2, time_limits=(5.0,), progress=lambda d, t, _: calls.append((d, t))
    )
    assert [(r.planner, r.mode) for r in runs] == [
        ("grid", "without"), ("grid", "with"),
        ("rrtconnect", "without"), ("rrtconnect", "with"), ("rrtconnect", "without"), ("rrtconnect", "with"),
    ]  # fmt: skip
    assert calls[0] == (0, 6) and calls[-1] == (6, 6) and len(calls) == 7
    assert all(r.cost_ratio >= 0.99 for r in runs)  # against the grid path on the same costmap
    with pytest.raises(ValueError, match="runs must be at least 1"):
        run_matrix([task], ["grid"], runs=0)


def test_runs_that_would_be_pooled_into_one_row_are_refused(task):
    # Two scenarios of one name (or one planner given twice) were summed into one row of sid compare's table.
    other = copy.deepcopy(DEMO_SCENARIO)
    other["robot"]["goal"] = [1.0, 0.0, 0.0]
    with pytest.raises(ValueError, match=f"two scenarios are named {task.scenario.name!r}"):
        run_matrix([task, prepare(scenario_from_dict(other))], ["grid"])
    with pytest.raises(ValueError, match="planner grid is given twice"):
        run_matrix([task], ["grid", "grid"])


def test_an_impossible_task_is_named():
    data = copy.deepcopy(DEMO_SCENARIO)
    data["name"], data["robot"]["goal"] = "walled in", [5.0, -2.9, 0.0]  # the goal is in the wall
    task = prepare(scenario_from_dict(data))
    with pytest.raises(PlanningError, match="walled in: no path: goal"):
        run_matrix([task], ["grid"])


def test_an_impossible_task_stops_the_matrix_before_any_run(task):
    # sid compare on several scenarios planned every earlier one with every planner and seed, then stopped on the
    # last one's impossible task and wrote nothing.
    data = copy.deepcopy(DEMO_SCENARIO)
    data["name"], data["robot"]["goal"] = "walled in", [5.0, -2.9, 0.0]
    calls: list[str] = []
    with pytest.raises(PlanningError, match="walled in: no path: goal"):
        run_matrix([task, prepare(scenario_from_dict(data))], ["rrtconnect"], progress=lambda d, t, w: calls.append(w))
    assert calls == []


def test_a_task_whose_goal_is_its_start_has_no_ratios():
    # sid compare stopped with a ZeroDivisionError: the grid reference's cost and the "without" length are 0 m.
    data = copy.deepcopy(DEMO_SCENARIO)
    data["robot"]["goal"] = data["robot"]["start"]
    runs = run_matrix([prepare(scenario_from_dict(data))], ["grid", "bitstar"], runs=1)
    assert [r.result.success for r in runs] == [True] * 4
    assert all(r.metrics["path_length_m"] == 0.0 for r in runs)
    assert all(r.cost_ratio is r.raw_cost_ratio is r.detour is None for r in runs)
    assert summarise([r.record() for r in runs])[1]["median_cost_ratio"] is None


def test_zone_warnings_name_the_end_and_the_group():
    data = copy.deepcopy(DEMO_SCENARIO)
    data["robot"]["goal"] = [4.5, 0.0, 0.0]  # the conversation's o-space centre
    task = prepare(scenario_from_dict(data))
    (warning,) = zone_warnings(task.scenario, task.groups)
    assert warning.startswith("the goal lies inside the interaction zone of group (1, 2, 3): the path has to enter it")
    data["robot"]["start"], data["robot"]["goal"] = data["robot"]["goal"], DEMO_SCENARIO["robot"]["goal"]
    task = prepare(scenario_from_dict(data))
    (warning,) = zone_warnings(task.scenario, task.groups)
    assert warning.startswith("the start lies inside the interaction zone of group (1, 2, 3): the path has to leave it")
    task = prepare(demo_scenario())
    assert zone_warnings(task.scenario, task.groups) == []


def _record(social: bool, success: bool, **values) -> dict:
    base = {"planner": "p", "layout": "L", "social_layer": social, "success": success, "planning_time_s": 0.1}
    return base | {"ospace_intrusion_m": None, "crosses_group": None, "min_person_distance_m": None} | values


def test_summary_counts_failures_and_orders_without_first():
    records = [
        _record(True, True, ospace_intrusion_m=0.0, crosses_group=False, min_person_distance_m=1.3,
                length_ratio=1.1, detour=1.08, cost_ratio=1.01),
        _record(False, True, ospace_intrusion_m=1.0, crosses_group=True, min_person_distance_m=0.5,
                length_ratio=1.0, cost_ratio=1.0),
        _record(False, False, planning_time_s=0.3, length_ratio=None),
        _record(False, True, ospace_intrusion_m=0.0, crosses_group=False, min_person_distance_m=0.9,
                length_ratio=1.02, cost_ratio=1.04),
    ]  # fmt: skip
    without, with_ = summarise(records, ("planner",))
    assert (without["social_layer"], with_["social_layer"]) == (False, True)
    assert without["runs"] == 3 and without["success_rate"] == pytest.approx(2 / 3)
    assert without["intrusion_rate"] == 0.5 and without["crossing_rate"] == 0.5
    assert without["mean_intrusion_m"] == 0.5 and without["median_intrusion_when_intruding_m"] == 1.0
    assert without["median_min_person_distance_m"] == pytest.approx(0.7)
    assert without["worst_min_person_distance_m"] == 0.5
    assert without["median_cost_ratio"] == pytest.approx(1.02) and without["worst_cost_ratio"] == 1.04
    assert without["median_planning_time_s"] == pytest.approx(0.1) and without["median_detour"] is None
    assert with_["median_detour"] == 1.08 and with_["intrusion_rate"] == 0.0
    (by_layout,) = summarise([r for r in records if not r["social_layer"]], ("layout",))
    assert by_layout["layout"] == "L" and "planner" not in by_layout
    failed = summarise([_record(False, False)], ("planner",))[0]
    assert failed["success_rate"] == 0.0 and failed["intrusion_rate"] is None and failed["median_cost_ratio"] is None


def test_summary_does_not_depend_on_the_order_of_the_records():
    """Every order of the same runs gives the same rows (a statistic that skips a first or last run would not)."""
    records = [
        _record(False, True, ospace_intrusion_m=v, crosses_group=v > 0, min_person_distance_m=d, length_ratio=lr,
                cost_ratio=c, planning_time_s=t)
        for v, d, lr, c, t in [(0.0, 1.3, 1.1, 1.01, 0.1), (0.7, 0.4, 1.0, 1.0, 0.2), (0.0, 0.9, 1.2, 1.3, 0.4),
                               (0.2, 0.6, 1.05, 1.2, 0.3)]
    ]  # fmt: skip
    expected = summarise(records)
    for permutation in itertools.permutations(records):
        assert summarise(list(permutation)) == expected
    (row,) = expected
    assert row["intrusion_rate"] == 0.5 and row["crossing_rate"] == 0.5 and row["worst_min_person_distance_m"] == 0.4
    assert row["worst_cost_ratio"] == 1.3 and row["mean_intrusion_m"] == pytest.approx(0.225)


def test_a_goal_on_a_person_is_refused_naming_the_person():
    data = copy.deepcopy(DEMO_SCENARIO)
    data["robot"]["goal"] = [7.5, 1.45, 0.0]  # 0.11 m from the lone person 4 at (7.6, 1.5)
    task = prepare(scenario_from_dict(data))
    for planner in ("grid", "bitstar"):
        with pytest.raises(NoPathError) as caught:
            compare_with_without(task, planner, 0.2, seed=1, modes=("with",))
        assert str(caught.value) == (
            "no path: goal (7.50, 1.45) is in collision: it lies inside an obstacle (cell cost 254, lethal); "
            "the goal is 0.11 m from person 4 at (7.60, 1.50): a person is an obstacle of radius 0.20 m "
            "(lidar.body_radius) and the robot a disc of radius 0.25 m (robot.radius)"
        )
    data["robot"]["goal"] = [8.05, 1.5, 0.0]  # 0.45 m away: the robot's disc just clear of the body
    comparison = compare_with_without(prepare(scenario_from_dict(data)), "grid", 0.2, modes=("with",))
    assert comparison.runs["with"].result.success


def test_people_at_ends_names_the_nearest_person_to_each_end_in_reach():
    data = copy.deepcopy(DEMO_SCENARIO)
    data["robot"]["start"], data["robot"]["goal"] = [3.75, -0.3, 0.0], [9.0, 0.0, 0.0]
    (sentence,) = people_at_ends(scenario_from_dict(data))
    assert sentence.startswith("the start is 0.15 m from person 2 at (3.72, -0.45)")
    assert people_at_ends(demo_scenario()) == []


def _corridor(people: list[dict], wall_across: bool = False) -> dict:
    """A corridor 1.6 m wide, 12 m long, the robot's way along it; ``wall_across`` closes it at x = 9."""
    obstacles = [{"type": "segment", "points": [[0, 0], [12, 0]]}, {"type": "segment", "points": [[0, 1.6], [12, 1.6]]}]
    if wall_across:
        obstacles.append({"type": "segment", "points": [[9, 0], [9, 1.6]]})
    return {
        "map": {"origin": [0, -0.4], "size": [12, 2.4]},
        "obstacles": obstacles,
        "people": people,
        "robot": {"start": [0.6, 0.8, 0], "goal": [11.4, 0.8, 0]},
    }


PAIR_ACROSS = [{"id": 1, "x": 6.0, "y": 0.35, "theta": 1.5708}, {"id": 2, "x": 6.0, "y": 1.25, "theta": -1.5708}]


@pytest.mark.parametrize("mode", ["with", "without"])
def test_a_way_closed_by_people_names_them(mode):
    """Two people talking across a 1.6 m corridor leave no gap for the robot's disc: the no-path message says who."""
    task = prepare(scenario_from_dict(_corridor(PAIR_ACROSS + [{"id": 3, "x": 3.0, "y": 0.4, "theta": 0.0}])))
    with pytest.raises(WalledOffError) as caught:
        task.plan(mode, "grid")
    assert str(caught.value) == (
        "no path: the start and the goal lie in separate free regions of the costmap (walled off from each other "
        "for a robot of radius 0.25 m); people 1 at (6.00, 0.35), 2 at (6.00, 1.25) close the way between them "
        "(without people it is open): a person is an obstacle of radius 0.20 m (lidar.body_radius) and the robot a "
        "disc of radius 0.25 m (robot.radius)"
    )  # person 3 stands in the corridor too, on the start's side only: not named


def test_two_pairs_closing_the_corridor_one_after_the_other_are_all_named():
    """Each pair's piece of wall borders a region between them, not both ends' regions: the message named nobody,
    and the user looked for a fault in the map (a probe's corridor_two_blockers). Pieces on a shortest chain of
    regions from the start to the goal count now; a person off that chain (3, on the start's side) still does not."""
    second = [{**p, "id": p["id"] + 10, "x": 9.0} for p in PAIR_ACROSS]
    task = prepare(scenario_from_dict(_corridor(PAIR_ACROSS + second + [{"id": 3, "x": 3.0, "y": 0.4, "theta": 0.0}])))
    assert people_walling_off(task.scenario, task.problems["with"]).startswith(
        "people 1 at (6.00, 0.35), 2 at (6.00, 1.25), 11 at (9.00, 0.35), 12 at (9.00, 1.25) close the way"
    )


def test_people_walling_off_is_none_when_the_map_alone_closes_the_way_or_nothing_does():
    walled = prepare(scenario_from_dict(_corridor(PAIR_ACROSS, wall_across=True)))
    assert people_walling_off(walled.scenario, walled.problems["with"]) is None
    with pytest.raises(WalledOffError, match=r"robot of radius 0.25 m\)$"):
        walled.plan("with", "grid")
    one = [{"id": 1, "x": 6.0, "y": 0.35, "theta": 1.5708}]  # one person leaves room to pass
    task = prepare(scenario_from_dict(_corridor(one)))
    assert people_walling_off(task.scenario, task.problems["with"]) is None


def test_people_against_the_walls_who_close_the_way_are_named():
    """A person whose centre lies where the robot cannot stand anyway (0.3 m from a wall, inside a box) still
    closes the way with their body: named, as the one inside the box is not."""
    people = [{"id": 1, "x": 6.0, "y": 0.3, "theta": 1.5708}, {"id": 2, "x": 6.0, "y": 1.3, "theta": -1.5708}]
    task = prepare(scenario_from_dict(_corridor(people)))
    assert people_walling_off(task.scenario, task.problems["with"]).startswith(
        "people 1 at (6.00, 0.30), 2 at (6.00, 1.30) close the way"
    )
    boxed = _corridor([people[1], {"id": 3, "x": 6.0, "y": 0.2, "theta": 0.0}])
    boxed["obstacles"].append({"type": "box", "min": [5.5, 0.0], "max": [6.5, 0.5]})
    with pytest.warns(InputWarning, match=r"person 3 at \(6, 0.2\) stands in an occupied cell of the known map"):
        task = prepare(scenario_from_dict(boxed))
    assert people_walling_off(task.scenario, task.problems["with"]).startswith("person 2 at (6.00, 1.30) closes")
