"""G-MITRE link counts on partitions worked out by hand."""

from __future__ import annotations

import pytest

from sid.experiments.gmitre import LinkCounts, gmitre_counts


def test_the_truth_against_itself_is_perfect_singletons_included() -> None:
    truth = [{1, 2, 3}, {4}, {5}]
    counts = gmitre_counts(truth, truth)
    assert counts == LinkCounts(4, 4, 4, 4)  # 2 links in the triple + 1 per doubled singleton, on both sides
    assert counts.f1 == 1.0


def test_a_group_cut_in_two_loses_recall_not_precision() -> None:
    # truth {1,2,3,4}: 3 links; found {1,2} {3,4}: the truth cut into 2 parts -> 2 of 3 links; each found pair whole
    counts = gmitre_counts([{1, 2, 3, 4}], [{1, 2}, {3, 4}])
    assert (counts.recall_hits, counts.recall_links) == (2, 3)
    assert (counts.precision_hits, counts.precision_links) == (2, 2)
    assert counts.f1 == pytest.approx(2 * 1.0 * (2 / 3) / (1 + 2 / 3))


def test_a_person_alone_on_one_side_only_is_a_missed_link_on_both() -> None:
    # truth: 1 and 2 walk together, 3 alone; found: everyone alone (people missing from a side are alone there)
    counts = gmitre_counts([{1, 2}, {3}], [{3}])
    assert (counts.recall_hits, counts.recall_links) == (1, 2)  # the pair's link lost, 3's own link kept
    assert (counts.precision_hits, counts.precision_links) == (1, 3)  # {1}, {2} wrong alone, {3} right


def test_counts_add_up_over_frames_and_empty_frames_count_nothing() -> None:
    one = gmitre_counts([{1, 2}], [{1, 2}])
    assert one + gmitre_counts([], []) == one
    assert (one + gmitre_counts([{1, 2}], [{1}, {2}])).recall == pytest.approx(0.5)
    assert LinkCounts().f1 == 1.0  # nothing to score: perfect by convention, as precision and recall


def test_a_person_in_two_groups_is_refused() -> None:
    with pytest.raises(ValueError, match="person 2 is in two found groups"):
        gmitre_counts([{1, 2, 3}], [{1, 2}, {2, 3}])
