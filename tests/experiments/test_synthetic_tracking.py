"""The tracking evaluation (MOTA / IDF1, group F1 with and without tracking, walkers, flicker) on short runs."""

from __future__ import annotations

import importlib.util
import math
import re
import sys
from collections import Counter
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest

from sid.distribution import install_hint
from sid.experiments import synthetic_tracking
from sid.experiments.crowd import evaluate_crowd
from sid.experiments.synthetic_tracking import (
    MissingDependencyError,
    TrackingEvalSettings,
    as_truth_ids,
    evaluate_tracking,
    identify,
    measure_flicker,
    mot_scores,
)
from sid.synthetic.sequence import builtin_sequence

pytestmark = pytest.mark.skipif(importlib.util.find_spec("motmetrics") is None, reason="py-motmetrics not installed")


def test_a_short_run_scores_people_groups_and_flicker() -> None:
    settings = TrackingEvalSettings(sequences=("crossing_walkers",), frames=24, flicker_layout="S1", flicker_frames=24)
    result = evaluate_tracking(settings)
    scores = result["sequences"]["crossing_walkers"]
    assert scores["frames"] == 24 and scores["objects"] == 5 * 24
    assert scores["misses"] == 5 * 2  # each of the five is reported from its third frame on
    assert scores["false_positives"] == 0 and scores["id_switches"] == 0
    assert scores["mota"] == pytest.approx(1 - 10 / 120) and scores["idf1"] >= 0.9
    f1 = scores["group_f1_T2/3"]
    assert f1["with_tracking"]["f1"] >= f1["without_tracking"]["f1"] and f1["with_tracking"]["frames"] == 9
    assert scores["frames_walkers_in_a_conversation"] == {"without_tracking": 0, "with_tracking": 0}
    assert result["overall"]["mota"] == pytest.approx(scores["mota"])
    flicker = result["flicker"]
    assert flicker["pairs_scored"] == 24 - 15  # from the first second on, at 15 fps
    assert flicker["tracked"]["changed_cells_total"] <= flicker["per_frame"]["changed_cells_total"]


def test_flicker_counts_the_cells_a_missed_person_leaves_blank() -> None:
    result = measure_flicker(TrackingEvalSettings(flicker_layout="S1", flicker_frames=40, flicker_miss_rate=0.3))
    assert result["per_frame"]["changed_cells_total"] > 1000  # a missed person's body and zone vanish for a frame
    assert result["tracked"]["changed_cells_total"] == 0


def test_people_are_identified_by_nearest_position_within_the_gate() -> None:
    truth = np.array([[1.0, 0.0], [2.0, 0.0]])
    found = np.array([[2.1, 0.0], [5.0, 5.0], [1.05, 0.0]])
    assert identify(found, [7, 8], truth, 0.5) == [8, None, 7]
    assert as_truth_ids([(0, 1, 2)], [0, 1, 2], [8, None, 7]) == [frozenset({8, -2, 7})]


def test_a_missing_motmetrics_is_explained(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(synthetic_tracking.importlib.util, "find_spec", lambda name: None)
    with pytest.raises(MissingDependencyError, match=re.escape(install_hint("eval"))):
        evaluate_tracking(TrackingEvalSettings(sequences=("walking_pairs",), frames=2))


@dataclass
class _Walkers:
    """A sequence's walkers (true ids) through the replay: the track ids identified with each, the frames each counts
    as ground truth and those with a track on them, the longest run (s) of such frames without a detection matched to
    that track (it coasts), and the walkers' closest approach (m, centre to centre)."""

    tracks: dict[int, set[int]] = field(default_factory=dict)
    truth_frames: Counter[int] = field(default_factory=Counter)
    tracked_frames: Counter[int] = field(default_factory=Counter)
    longest_coast: dict[int, float] = field(default_factory=dict)
    closest: float = math.inf


def _replay(name: str, seconds: float) -> tuple[dict[str, Any], _Walkers]:
    """The first ``seconds`` of a built-in sequence through the replay of ``sid eval tracking`` (the pipeline on
    ``TruthPose``, a ``SocialStream``): its motmetrics scores, and its two walkers identified as the evaluation
    identifies people (minimum total distance within its match distance)."""
    settings = TrackingEvalSettings(sequences=(name,), frames=round(seconds * TrackingEvalSettings().fps) + 1)
    logs = synthetic_tracking._run_sequence(name, settings, None)
    scores = mot_scores([synthetic_tracking._accumulate(logs, settings.match_distance)], [name])[name]
    walkers = sorted(p.id for p in builtin_sequence(name).people if p.trajectory.path)
    out = _Walkers({w: set() for w in walkers}, longest_coast=dict.fromkeys(walkers, 0.0))
    coasting = dict.fromkeys(walkers, 0)
    for log in logs:
        ids = [p.id for p in log.truth.people]
        positions = np.array([[p.x, p.y] for p in log.truth.people])
        seen = dict(zip(ids, synthetic_tracking._seen(log).tolist(), strict=True))
        track_of = dict(
            zip(identify(log.track_positions, ids, positions, settings.match_distance), log.track_ids, strict=True)
        )
        visible = dict(zip(log.track_ids, log.track_visible.tolist(), strict=True))
        for w in walkers:
            if w in track_of:
                out.tracks[w].add(track_of[w])
            out.truth_frames[w] += seen[w]
            out.tracked_frames[w] += seen[w] and w in track_of
            coasting[w] = coasting[w] + 1 if seen[w] and not visible.get(track_of.get(w), False) else 0
            out.longest_coast[w] = max(out.longest_coast[w], coasting[w] / settings.fps)
        first, second = (positions[ids.index(w)] for w in walkers)
        out.closest = min(out.closest, float(np.linalg.norm(first - second)))
    return scores, out


def _assert_one_track_each(scores: dict[str, Any], walkers: _Walkers) -> None:
    assert scores["id_switches"] == 0 and scores["id_transfers"] == 0
    assert all(len(ids) == 1 for ids in walkers.tracks.values()), walkers.tracks
    assert len(set.union(*walkers.tracks.values())) == len(walkers.tracks)  # one track each, not one for both
    for w, frames in walkers.truth_frames.items():  # so it cannot pass by tracking nobody
        assert frames >= 30 and walkers.tracked_frames[w] >= 0.85 * frames, (w, walkers.tracked_frames[w], frames)


def test_walkers_in_file_behind_a_group_keep_their_tracks() -> None:
    scores, walkers = _replay("file_behind_group", 4.6)  # until both are out from behind the group
    _assert_one_track_each(scores, walkers)
    assert walkers.longest_coast[4] > 1.2  # the leader goes undetected behind the group for more than a second


def test_walkers_crossing_closer_than_0_4_m_keep_their_tracks() -> None:
    scores, walkers = _replay("close_crossing", 3.5)  # a second past the crossing
    _assert_one_track_each(scores, walkers)
    assert walkers.closest < 0.4


def test_both_evaluations_refuse_a_missing_motmetrics_with_the_one_message(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "motmetrics", None)  # as if not installed: find_spec answers None
    messages = []
    for evaluate in (evaluate_tracking, lambda: evaluate_crowd([])):
        with pytest.raises(MissingDependencyError, match="needs py-motmetrics") as info:
            evaluate()
        messages.append(str(info.value))
    assert messages[0] == messages[1]
    assert install_hint("eval") in messages[0]
