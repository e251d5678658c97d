"""The tracking evaluation (MOTA / IDF1, group F1 with and without tracking, walkers, flicker) on short runs."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from sid.experiments import tracking
from sid.experiments.tracking import (
    MissingDependencyError,
    TrackingEvalSettings,
    as_truth_ids,
    evaluate_tracking,
    identify,
    measure_flicker,
)

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
    monkeypatch.setattr(tracking.importlib.util, "find_spec", lambda name: None)
    with pytest.raises(MissingDependencyError, match=r"pip install 'sid\[eval\]'"):
        evaluate_tracking(TrackingEvalSettings(sequences=("walking_pairs",), frames=2))
