"""The crowd evaluation (sid eval crowd) on a trajectory set written here, and on the shared real sets."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from sid.checks import LimitError
from sid.experiments.crowd import EVALUATION_PASSES, CrowdSettings, cross_validate, evaluate_crowd
from sid.experiments.trajectories import ReplaySettings, TrajectoryError, load_trajectory_set
from sid.tracking.view import ViewCone
from tests.conftest import shared_path
from tests.experiments.trajectory_files import pair_and_strangers, write_set

pytestmark = pytest.mark.skipif(importlib.util.find_spec("motmetrics") is None, reason="py-motmetrics not installed")


def test_a_clean_scene_is_tracked_and_grouped_without_mistakes(tmp_path: Path) -> None:
    scene = load_trajectory_set(pair_and_strangers(tmp_path / "scene"))
    settings = CrowdSettings(replay=ReplaySettings(noise=0.05, miss_rate=0.0))
    result = evaluate_crowd([scene], settings)["sets"]["scene"]
    people, groups = result["people"], result["groups"]
    assert people["id_switches"] == 0 and people["idf1"] > 0.9 and people["true_tracks"] == 4
    # the pair's link is missed only while the tracks and the group are confirmed, early on (on both sides in G-MITRE)
    assert groups["gmitre"]["precision"] > 0.9 and groups["gmitre"]["recall"] > 0.9
    assert groups["groups_T2/3"]["precision"] == 1.0 and groups["groups_T2/3"]["true_groups"] == 40
    assert result["coherent_motion"]["groups_T2/3"]["precision"] == 1.0


def test_progress_counts_every_pass_over_the_frames_not_only_the_tracking(tmp_path: Path) -> None:
    """The count reached 100 % after the tracking, the first of six passes: with 65 people at 15 Hz the other five
    took 35 s per set without a line."""
    scene = load_trajectory_set(pair_and_strangers(tmp_path / "scene", frames=10))
    calls: list[tuple[int, int, str]] = []
    evaluate_crowd([scene], CrowdSettings(), lambda done, total, what: calls.append((done, total, what)))
    assert [done for done, _, _ in calls] == list(range(1, 61)) and {total for _, total, _ in calls} == {60}
    assert [what for _, _, what in calls[::10]] == [f"scene: {name}" for name in EVALUATION_PASSES]


def test_a_replay_that_cannot_be_scored_or_would_not_end_is_refused_naming_the_set(tmp_path: Path) -> None:
    scene = load_trajectory_set(pair_and_strangers(tmp_path / "scene", frames=5))
    # A robot looking away from everyone: MOTA and IDF1 were NaN (invalid JSON from --json).
    away = ReplaySettings(view=ViewCone(-5.0, 0.0, 3.14, 1.0))
    with pytest.raises(TrajectoryError, match="scene: nobody annotated is ever inside the view"):
        evaluate_crowd([scene], CrowdSettings(replay=away))
    # Everyone on one line: no scene area to draw (the message used to name neither the set nor a way out).
    line = load_trajectory_set(write_set(tmp_path / "line", [(k, p, p, 0, p, 0, 0, 0) for k in (0, 6) for p in (1, 2)]))
    with pytest.raises(TrajectoryError, match=r"line: view: the positions span no area .*\(--view\)"):
        evaluate_crowd([scene, line])
    # A gap of 2^53 frames at 1 Hz: 3.6e15 empty frames, a hang; refused before the first set runs.
    rows = [(k, p, p, 0, p * p, 0, 0, 0) for k in (0, 1, 2**53) for p in (1, 2, 3)]
    gap = load_trajectory_set(write_set(tmp_path / "gap", rows))
    with pytest.raises(LimitError, match="gap: replay: .* frames is more than the limit of 1,000,000 frames"):
        evaluate_crowd([scene, gap], CrowdSettings(replay=ReplaySettings(rate=1.0)))


def test_cross_validation_reports_each_held_out_set(tmp_path: Path) -> None:
    sets = [load_trajectory_set(pair_and_strangers(tmp_path / name, frames=15)) for name in ("a", "b")]
    grid = {
        "tracker": {"timeout": (1.0, 1.5)},
        "groups": {"walk_distance": (1.0, 2.0)},
        "coherent": {"share": (0.5, 1.0)},
    }
    result = cross_validate(sets, CrowdSettings(), grid)
    assert [fold["held_out"] for fold in result["folds"]] == ["a", "b"]
    for fold in result["folds"]:
        assert fold["tracker"]["chosen"]["timeout"] in (1.0, 1.5) and 0.5 < fold["tracker"]["held_out_idf1"] <= 1
        assert fold["groups"]["chosen"]["walk_distance"] in (1.0, 2.0)
        assert 0.0 <= fold["coherent"]["held_out_f1"] <= 1.0


def test_the_shared_sets_are_scored_with_both_group_trackers() -> None:
    zara = load_trajectory_set(shared_path("data", "trajectories", "zara01"))
    result = evaluate_crowd([zara])["sets"]["zara01"]
    assert result["frames"] == len(zara.times)
    assert 0.5 < result["people"]["idf1"] <= 1.0 and 0.5 < result["people"]["mota"] <= 1.0
    for which in ("groups", "coherent_motion"):
        assert 0.3 < result[which]["gmitre"]["f1"] <= 1.0
        assert result[which]["groups_T2/3"]["true_groups"] == result["groups"]["groups_T2/3"]["true_groups"] > 100
