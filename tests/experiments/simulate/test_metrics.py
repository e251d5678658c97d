import math

import numpy as np
import pytest

from sid.experiments.path_metrics import path_metrics
from sid.experiments.simulate.loop import RunTrace
from sid.experiments.simulate.metrics import run_metrics
from sid.perception.groups import detect_groups
from sid.perception.people import Person

PAIR = [Person(1, 2.0, 0.7, -1.5708, 1.0), Person(2, 2.0, -0.7, 1.5708, 1.0)]


def _trace(ys: list[float], success: bool = True) -> RunTrace:
    groups = detect_groups(PAIR)
    trace = RunTrace(success, "goal reached", 0, 0.5 * (len(ys) - 1))
    trace.trajectory = [(0.5 * i, 0.5 * i, y, 0.0) for i, y in enumerate(ys)]
    trace.truth = [(PAIR, groups)] * len(ys)
    return trace


def test_a_trajectory_through_the_pair_intrudes_and_crosses():
    metrics = run_metrics(_trace([0.0] * 9), 4.0)
    assert metrics["success"] and metrics["time_to_goal_s"] == 4.0
    assert metrics["path_length_m"] == pytest.approx(4.0)
    assert metrics["ospace_intrusion_m"] > 0.5 and metrics["crosses_group"]
    assert metrics["min_person_distance_m"] == pytest.approx(0.7)
    assert len(metrics["trajectory"]) == 9


def test_a_trajectory_far_from_the_pair_does_not():
    metrics = run_metrics(_trace([-2.5] * 9, success=False), 4.0)
    assert metrics["ospace_intrusion_m"] == 0.0 and not metrics["crosses_group"]
    assert metrics["min_person_distance_m"] == pytest.approx(1.8)
    assert metrics["time_to_goal_s"] is None and metrics["length_ratio"] is None


def test_personal_space_is_the_share_of_the_driven_path_as_for_a_planned_path():
    """Ten steps waiting 1 m from someone, then 4 m along x in 1 m steps: within 1.2 m for 0.66 m of the 4 m."""
    person = [Person(1, 0.0, 1.0, 0.0, 1.0)]
    xs = [0.0] * 10 + [1.0, 2.0, 3.0, 4.0]
    trace = RunTrace(True, "goal reached", 0, float(len(xs) - 1))
    trace.trajectory = [(float(k), x, 0.0, 0.0) for k, x in enumerate(xs)]
    trace.truth = [(person, [])] * len(xs)
    driven = path_metrics(np.array([(x, 0.0) for x in (0.0, 1.0, 2.0, 3.0, 4.0)]), person, [])
    metrics = run_metrics(trace, 4.0)
    assert metrics["personal_space_fraction"] == pytest.approx(driven["personal_space_fraction"])
    assert metrics["personal_space_fraction"] == pytest.approx(math.sqrt(1.2**2 - 1) / 4, abs=0.01)
