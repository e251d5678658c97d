"""The crowd evaluation (sid eval crowd) on a trajectory set written here, and on the shared real sets."""

from __future__ import annotations

import importlib.util
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from sid.checks import LimitError
from sid.experiments import crowd
from sid.experiments.crowd import (
    EVALUATION_PASSES,
    CrowdSettings,
    TrackLog,
    cross_validate,
    evaluate_crowd,
    find_groups,
    record_tracks,
    replay_view,
    reported_log,
    score_people,
)
from sid.experiments.synthetic_tracking import mot_scores
from sid.experiments.trajectories import ReplaySettings, TrajectoryError, TrajectorySet, load_trajectory_set, replay
from sid.tracking.session import TrackingSession
from sid.tracking.tracker import TimeGapWarning
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


def test_switches_per_100_tracks_count_only_the_people_scored_inside_the_view(tmp_path: Path) -> None:
    scene = load_trajectory_set(pair_and_strangers(tmp_path / "scene"))
    # 6 m around (9.5, 0.3): the pair and stranger 3 (y = 4) pass through it, stranger 4 (y = 7) never comes nearer
    # than 6.7 m, so only three people are ever scored.
    view = ViewCone(9.5, 0.3, 0.0, 2 * math.pi, 6.0)
    settings = CrowdSettings(replay=ReplaySettings(noise=0.05, miss_rate=0.0, view=view))
    log = record_tracks(scene, settings)
    assert {int(i) for ids in log.truth_ids for i in ids} == {1, 2, 3}
    people = evaluate_crowd([scene], settings)["sets"]["scene"]["people"]
    assert people["true_tracks"] == 3
    assert people["id_switches_per_100_tracks"] == pytest.approx(100 * people["id_switches"] / 3)


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
        "reporting": {"report_timeout": (0.4, 1.5)},
    }
    result = cross_validate(sets, CrowdSettings(), grid)
    assert [fold["held_out"] for fold in result["folds"]] == ["a", "b"]
    for fold in result["folds"]:
        assert fold["tracker"]["chosen"]["timeout"] in (1.0, 1.5) and 0.5 < fold["tracker"]["held_out_idf1"] <= 1
        assert fold["groups"]["chosen"]["walk_distance"] in (1.0, 2.0)
        assert 0.0 <= fold["coherent"]["held_out_f1"] <= 1.0
        assert fold["reporting"]["chosen"]["report_timeout"] in (0.4, 1.5)
        assert 0.5 < fold["reporting"]["held_out_idf1"] <= 1
    calls: list[tuple[int, int, str]] = []
    pooled = cross_validate(sets, CrowdSettings(), grid, lambda *call: calls.append(call), workers=2)
    assert pooled == result  # the same folds from worker processes
    finished = [(total, what) for done, total, what in calls if done == total]  # each stage's last call
    assert finished[0] == (2, "tracker points")  # then each chosen tracker's groups, and each fold's reporting
    groups = [(total, what) for total, what in finished[1:] if what.startswith("group points on tracker ")]
    assert 1 <= len(groups) <= 2 and all(total == 4 for total, _ in groups)
    assert [f for f in finished[1:] if f not in groups] == [
        (2, "reporting points, a held out"),
        (2, "reporting points, b held out"),
    ]


def assert_scored_as_reported(scene: TrajectorySet) -> int:
    """One rule for what is reported (``split_reported``): frame by frame, the evaluation's groups are the session's
    and its hypotheses the people ``TrackingSession.track`` reports (detected or in view); the held tracks in view."""
    settings = CrowdSettings()
    log = record_tracks(scene, settings)
    found = find_groups(log, settings.tracking.groups)
    scored, shown = reported_log(log, found, settings.tracking.report_timeout)
    session, view, held = TrackingSession(settings.tracking), replay_view(scene, settings.replay), 0
    for k, frame in enumerate(replay(scene, settings.replay)):
        with warnings.catch_warnings():  # the real sets' annotations pause for seconds, as record_tracks says
            warnings.simplefilter("ignore", TimeGapWarning)
            update = session.track(frame.detections, frame.timestamp, view)
        assert [p.id for p in update.people if p.visible or p.in_view] == [p.id for p in scored.tracks[k]]
        assert sorted(sorted(g.members) for g in update.groups) == sorted(sorted(g) for g in shown[k])
        assert sorted(sorted(g.members) for g in update.held_groups + update.groups) == sorted(map(sorted, found[k]))
        held += sum(p.in_view for p in update.held)
    return held


def test_the_people_scored_are_those_the_tracking_session_reports(tmp_path: Path) -> None:
    assert assert_scored_as_reported(load_trajectory_set(crossing_crowds(tmp_path / "crowds", crowds=2))) > 5


def test_the_people_scored_on_a_real_set_are_those_the_tracking_session_reports() -> None:
    """seq_eth: a walking pair whose one member left the view held the other, coasting in view, in the session,
    and the evaluation, whose group tracker saw only the tracks in view, did not (15 frames)."""
    assert assert_scored_as_reported(load_trajectory_set(shared_path("data", "trajectories", "seq_eth"))) > 100


def crossing_crowds(folder: Path, crowds: int = 5, walkers: int = 6) -> Path:
    """``crowds`` scenes 30 m apart, in each ``walkers`` people crossing its centre from a 5 m circle at 1.2 m/s,
    starting up to 4 s apart: close passes, so the noisy replay makes switches, misses and false tracks."""
    rng = np.random.default_rng(3)
    rows: list[tuple[float, ...]] = []
    for c in range(crowds):
        for w in range(walkers):
            heading, start = rng.uniform(0, math.tau), int(rng.integers(0, 10))
            for step in range(21):
                x, y = 30.0 * c + (-5 + 0.48 * step) * math.cos(heading), (-5 + 0.48 * step) * math.sin(heading)
                vx, vy = 1.2 * math.cos(heading), 1.2 * math.sin(heading)
                rows.append((start + step, 10 * c + w + 1, x, 0, y, vx, 0, vy))
    return write_set(folder, sorted(rows), "")


def one_accumulator_scores(log: TrackLog, match_distance: float) -> dict[str, float]:
    import motmetrics

    accumulator = motmetrics.MOTAccumulator(auto_id=True)
    for k in range(len(log.times)):
        distances = motmetrics.distances.norm2squared_matrix(
            log.truth_positions[k], log.track_positions(k), max_d2=match_distance**2
        )
        accumulator.update(log.truth_ids[k].tolist(), [p.id for p in log.tracks[k]], distances)
    return mot_scores([accumulator], ["whole"])["whole"]


def assert_scored_in_parts_as_one(scene: TrajectorySet, monkeypatch: pytest.MonkeyPatch, part_ids: int) -> int:
    """The people's scores of ``scene`` in parts of at most ``part_ids`` ids equal one accumulator's; the parts."""
    settings = CrowdSettings()
    log = record_tracks(scene, settings)
    monkeypatch.setattr(crowd, "MOT_PART_IDS", part_ids)
    whole, parts = (
        one_accumulator_scores(log, settings.match_distance),
        score_people(log, settings.match_distance),
    )
    for name, value in whole.items():
        assert parts[name] == (pytest.approx(value, rel=1e-12) if name == "motp_m" else value), name
    return len(crowd._accumulate(log, settings.match_distance))


def test_people_are_scored_in_independent_parts_exactly_as_in_one_accumulator(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """motmetrics' identity matching is a dense square over every id of an accumulator: one accumulator over 5 300
    people and their tracks took 4 GB; parts of people and tracks never within the match distance of each other
    score the same."""
    scene = load_trajectory_set(crossing_crowds(tmp_path / "crowds"))
    whole = evaluate_crowd([scene])["sets"]["crowds"]["people"]
    assert whole["id_switches"] + whole["misses"] + whole["false_positives"] > 0  # mistakes to keep apart
    assert assert_scored_in_parts_as_one(scene, monkeypatch, part_ids=8) >= 5  # a crowd never shares a part
    assert assert_scored_in_parts_as_one(scene, monkeypatch, part_ids=10**6) == 1


@pytest.mark.parametrize("name", ["seq_eth", "seq_hotel", "zara01"])
def test_the_shared_sets_score_the_same_in_parts(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    scene = load_trajectory_set(shared_path("data", "trajectories", name))
    assert assert_scored_in_parts_as_one(scene, monkeypatch, part_ids=50) > 5


def test_the_shared_sets_are_scored_with_both_group_trackers() -> None:
    zara = load_trajectory_set(shared_path("data", "trajectories", "zara01"))
    result = evaluate_crowd([zara])["sets"]["zara01"]
    assert result["frames"] == len(zara.times)
    assert 0.5 < result["people"]["idf1"] <= 1.0 and 0.5 < result["people"]["mota"] <= 1.0
    for which in ("groups", "coherent_motion"):
        assert 0.3 < result[which]["gmitre"]["f1"] <= 1.0
        assert result[which]["groups_T2/3"]["true_groups"] == result["groups"]["groups_T2/3"]["true_groups"] > 100
