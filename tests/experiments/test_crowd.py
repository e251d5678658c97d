"""The crowd evaluation (sid eval crowd) on a trajectory set written here, and on the shared real sets."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from sid.experiments.crowd import CrowdSettings, cross_validate, evaluate_crowd
from sid.experiments.trajectories import ReplaySettings, load_trajectory_set
from tests.conftest import shared_path

pytestmark = pytest.mark.skipif(importlib.util.find_spec("motmetrics") is None, reason="py-motmetrics not installed")


def _write_scene(folder: Path, frames: int = 40) -> Path:
    """Pedestrians 1 and 2 walk side by side (0.6 m apart, +x, 1.2 m/s), 3 and 4 alone the other way 4 m away."""
    folder.mkdir(parents=True)
    rows = []
    for k in range(frames):
        x = 0.48 * k
        rows += [(k, 1, x, 0, 0.0, 1.2, 0, 0), (k, 2, x, 0, 0.6, 1.2, 0, 0)]
        rows += [(k, 3, 19 - x, 0, 4.0, -1.2, 0, 0), (k, 4, 19 - x, 0, 7.0, -1.2, 0, 0)]
    (folder / "obsmat.txt").write_text("\n".join(" ".join(str(v) for v in row) for row in rows) + "\n")
    (folder / "groups.txt").write_text("1 2\n")
    return folder


def test_a_clean_scene_is_tracked_and_grouped_without_mistakes(tmp_path: Path) -> None:
    scene = load_trajectory_set(_write_scene(tmp_path / "scene"))
    settings = CrowdSettings(replay=ReplaySettings(noise=0.05, miss_rate=0.0))
    result = evaluate_crowd([scene], settings)["sets"]["scene"]
    people, groups = result["people"], result["groups"]
    assert people["id_switches"] == 0 and people["idf1"] > 0.9 and people["true_tracks"] == 4
    # the pair's link is missed only while the tracks and the group are confirmed, early on (on both sides in G-MITRE)
    assert groups["gmitre"]["precision"] > 0.9 and groups["gmitre"]["recall"] > 0.9
    assert groups["groups_T2/3"]["precision"] == 1.0 and groups["groups_T2/3"]["true_groups"] == 40
    assert result["coherent_motion"]["groups_T2/3"]["precision"] == 1.0


def test_cross_validation_reports_each_held_out_set(tmp_path: Path) -> None:
    sets = [load_trajectory_set(_write_scene(tmp_path / name, frames=15)) for name in ("a", "b")]
    grid = {"groups": {"walk_distance": (1.0, 2.0)}, "coherent": {"share": (0.5, 1.0)}}
    result = cross_validate(sets, CrowdSettings(), grid)
    assert [fold["held_out"] for fold in result["folds"]] == ["a", "b"]
    for fold in result["folds"]:
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
