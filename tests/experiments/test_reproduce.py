"""``sid reproduce table1|navigation``: end-to-end smoke runs on tiny settings, their documented output fields, and
the accounting behind them (person matching, angle wrapping, misses counted, bad settings refused)."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import cv2
import numpy as np
import pytest

from sid.cli import main
from sid.experiments.navigation import NAV_LAYOUTS, RUN_KEYS, NavSettings, navigation_tasks
from sid.experiments.table1 import METRICS, PAPER_TABLE1, ErrorLog, Table1Settings, match_people, wrap_degrees
from sid.perception.groups import detect_groups
from sid.perception.people import Person
from sid.sources.synthetic import SyntheticSource
from sid.synthetic.noise import DepthNoise, KeypointNoise

SUMMARY_KEYS = {
    "planner", "social_layer", "runs", "success_rate", "intrusion_rate", "mean_intrusion_m", "median_intrusion_m",
    "median_intrusion_when_intruding_m", "crossing_rate", "median_min_person_distance_m",
    "worst_min_person_distance_m", "median_length_ratio", "median_detour", "median_planning_time_s",
    "median_cost_ratio", "worst_cost_ratio", "median_raw_cost_ratio",
}  # fmt: skip


def _truth(scene: str = "S3"):
    source = SyntheticSource(scene, frames=1, noise=DepthNoise.exact(), keypoint_noise=KeypointNoise(0, 0))
    return source[0].truth


def _people_from_truth(truth, offset=(0.0, 0.0), turn=0.0) -> list[Person]:
    return [Person(10 + p.id, p.x + offset[0], p.y + offset[1], p.theta + turn, 1.0) for p in truth.people]


# --- table 1 -----------------------------------------------------------------------------------------------------


def test_table1_command_writes_the_documented_fields(tmp_path, capsys):
    assert main(["reproduce", "table1", "--quick", "--scenarios", "S1", "s4", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "table1.json").read_text())
    assert data["paper"] == PAPER_TABLE1
    for name in ("S1", "S4"):
        row = data[name]
        assert set(METRICS) <= set(row)
        for metric in METRICS:
            assert row[metric] is None or (isinstance(row[metric], float) and row[metric] >= 0)
        assert row["frames"] == 2
        assert row["people"]["truth"] == 2 * (2 if name == "S1" else 4)
        assert 0 <= row["people"]["matched"] <= row["people"]["truth"]
        group = row["group"]
        assert group["found"] + group["not_found"] == group["frames"]
        assert set(row["bias"]) == set(METRICS) and set(row["samples"]) == set(METRICS)
        assert len(data["by_variation"][name]) == 1
    assert data["settings"]["frames_per_variation"] == 2
    text = (tmp_path / "table1.md").read_text()
    assert "| **S1** ours |" in text and "| S4 paper | 0.038 |" in text and "frames without group" in text
    assert "table1.md" in capsys.readouterr().out


# S3 (three people), 2 variations x 3 frames, seed 0: the whole row, measured with ``sid reproduce table1
# --scenarios S3 --frames 3 --variations 2``. Seeded noise makes it repeat exactly; 0.5 % leaves room for float
# noise across platforms and library versions, while any change to rendering, noise, lifting, facing or grouping
# moves these by more.
# With the lift's window depth search (issue 14); the exact search gave IZA 0.004655, IPX 0.024978, IPY 0.018595,
# HPX 0.014350, HPY 0.021854, HFD 2.4492.
S3_ROW = {"IZA": 0.004757, "IPX": 0.020993, "IPY": 0.022901, "HPX": 0.008095, "HPY": 0.020070, "HFD": 2.5901}


def test_table1_row_is_pinned_on_a_small_seeded_run(tmp_path):
    args = ["reproduce", "table1", "--scenarios", "S3", "--frames", "3", "--variations", "2", "--seed", "0"]
    assert main([*args, "--out", str(tmp_path)]) == 0
    row = json.loads((tmp_path / "table1.json").read_text())["S3"]
    assert {metric: row[metric] for metric in METRICS} == pytest.approx(S3_ROW, rel=5e-3)
    assert row["people"]["matched"] == row["people"]["truth"] == 18 and row["people"]["false_detections"] == 0
    assert row["group"]["found"] == row["group"]["exact_members"] == row["group"]["frames"] == 6


def test_table1_exact_option_removes_all_noise(tmp_path):
    assert main(["reproduce", "table1", "--quick", "--exact", "--scenarios", "S2", "--out", str(tmp_path)]) == 0
    settings = json.loads((tmp_path / "table1.json").read_text())["settings"]
    assert settings["depth_noise"]["subpixel"] == 0 and settings["depth_noise"]["hole_fraction"] == 0
    assert settings["keypoint_noise"] == {"sigma_px": 0.0, "drop": 0.0}


def test_table1_bad_settings_are_refused(tmp_path, capsys):
    assert main(["reproduce", "table1", "--scenarios", "S9", "--out", "unused"]) == 2
    assert "unknown scenario" in capsys.readouterr().err
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    assert main(["reproduce", "table1", "--quick", "--out", str(blocker / "out")]) == 2  # refused before the run
    assert (
        "--out " in (err := capsys.readouterr().err) and "cannot create the folder" in err and "a-file is a file" in err
    )
    with pytest.raises(ValueError, match="frames"):
        Table1Settings(frames=0)
    with pytest.raises(ValueError, match="table1: scenario S1 is given twice"):  # its frames were pooled twice
        Table1Settings(scenarios=("S1", "S2", "s1"))
    with pytest.raises(ValueError, match="variations"):
        Table1Settings(variations=8)
    with pytest.raises(ValueError, match="noise"):
        KeypointNoise(sigma_px=-1.0)


def test_people_are_matched_by_position_not_by_id():
    truth = _truth("S3")
    people = _people_from_truth(truth)[::-1]  # other ids, other order
    people.append(Person(99, 9.0, 9.0, 0.0, 1.0))  # nobody there: a false detection
    matches = match_people(people, truth, radius=0.5)
    assert matches == {10 + p.id: p.id for p in truth.people}
    assert match_people(_people_from_truth(truth, offset=(0.6, 0.0)), truth, radius=0.5) == {}
    assert match_people([], truth, radius=0.5) == {}


def test_people_are_matched_within_the_radius_even_when_an_unrestricted_assignment_would_pair_them_farther():
    truth = _truth("S3")
    near, far = truth.people[:2]
    truth = replace(truth, people=[replace(near, x=0.45, y=0.0), replace(far, x=-2.0, y=0.0)])
    # Unrestricted, (0, 0) -> (-2, 0) and (1, 0) -> (0.45, 0) cost least in total, and both pairs lie beyond 0.5 m.
    people = [Person(1, 0.0, 0.0, 0.0, 1.0), Person(2, 1.0, 0.0, 0.0, 1.0)]
    assert match_people(people, truth, radius=0.5) == {1: near.id}


def test_angle_differences_wrap():
    assert wrap_degrees(math.radians(179.0) - math.radians(-179.0)) == pytest.approx(-2.0)
    assert wrap_degrees(math.radians(-350.0)) == pytest.approx(10.0)


def test_error_log_counts_errors_and_misses():
    truth = _truth("S3")
    log = ErrorLog()
    people = _people_from_truth(truth, offset=(0.1, -0.2), turn=math.radians(4.0))
    log.add_frame(truth, people, detect_groups(people), radius=0.5)
    log.add_frame(truth, people[:1], [], radius=0.5)  # two people and the group missed
    summary = log.summary()
    assert summary["HPX"] == pytest.approx(0.1) and summary["HPY"] == pytest.approx(0.2)
    assert summary["bias"]["HPY"] == pytest.approx(-0.2) and summary["HFD"] == pytest.approx(4.0)
    assert summary["people"] == {
        "truth": 6, "matched": 4, "detection_rate": pytest.approx(4 / 6), "false_detections": 0, "without_facing": 0
    }  # fmt: skip
    group = summary["group"]
    assert (group["frames"], group["found"], group["exact_members"], group["not_found"]) == (2, 1, 1, 1)
    # A shifted group keeps its zone: the interest point moves with the people.
    assert summary["IPX"] == pytest.approx(0.1, abs=1e-6) and summary["IPY"] == pytest.approx(0.2, abs=1e-6)
    assert summary["samples"]["IZA"] == 1


# --- navigation --------------------------------------------------------------------------------------------------


def test_navigation_command_writes_the_documented_fields(tmp_path):
    assert main(["reproduce", "navigation", "--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "navigation.json").read_text())
    assert data["settings"]["planners"] == ["grid", "rrtconnect"]
    assert len(data["summary"]) == 4  # 2 planners x with/without
    for row in data["summary"]:
        assert set(row) == SUMMARY_KEYS
        assert 0.0 <= row["success_rate"] <= 1.0
    assert {r["layout"] for r in data["by_layout"]} == {"P2", "T3"}
    assert len(data["runs"]) == 2 * 2 * 2 * 2  # layouts x directions x planners x costmaps
    assert all(list(run) == list(RUN_KEYS) for run in data["runs"])
    with_runs = [r for r in data["runs"] if r["social_layer"] and r["success"]]
    assert all(r["detour"] > 0.9 for r in with_runs) and all(r["seed"] == 1 for r in data["runs"])  # the draw
    grid_with = next(r for r in data["summary"] if r["planner"] == "grid" and r["social_layer"])
    assert grid_with["success_rate"] == 1.0 and grid_with["intrusion_rate"] == 0.0  # the claim the demo makes
    text = (tmp_path / "navigation.md").read_text()
    assert "| grid | with |" in text and "intrusion rate" in text
    for name in ("navigation.png", "navigation_example.png"):
        image = cv2.imread(str(tmp_path / name))
        assert image is not None and image.shape[0] > 300 and image.shape[1] > 600
        assert len(np.unique(image.reshape(-1, 3), axis=0)) > 4  # drawn, not blank


def test_navigation_family_covers_sizes_and_finds_every_group():
    tasks = navigation_tasks(2)
    assert {t.group_size for t in tasks} == {2, 3, 4, 5}
    assert len(tasks) == len(NAV_LAYOUTS) * 2 * 2
    for task in tasks:
        found = detect_groups(task.scenario.people, task.scenario.group_params)
        assert [len(g.members) for g in found] == [task.group_size], task.name
        start, goal = task.scenario.robot.start, task.scenario.robot.goal
        assert abs(start[0] - goal[0]) == 9.0 and abs(start[1]) <= 0.6 and abs(goal[1]) <= 0.6
    reverse = next(t for t in tasks if t.direction == "reverse")
    forward = next(t for t in tasks if t.layout == reverse.layout and t.seed == reverse.seed and t is not reverse)
    assert reverse.scenario.robot.start[:2] == forward.scenario.robot.goal[:2]


def test_navigation_bad_settings_are_refused(capsys):
    with pytest.raises(ValueError, match="planner"):
        NavSettings(planners=("teleport",))
    with pytest.raises(ValueError, match="planner grid is given twice"):
        NavSettings(planners=("grid", "bitstar", "grid"))
    with pytest.raises(ValueError, match="time limit"):
        NavSettings(time_limit=0.0)
    with pytest.raises(ValueError, match="seeds"):
        navigation_tasks(0)
    with pytest.raises(ValueError, match="unknown navigation layout"):
        navigation_tasks(1, ["S7"])
    assert main(["reproduce", "navigation", "--layouts", "S7", "--out", "unused"]) == 2
    assert "unknown navigation layout" in capsys.readouterr().err
