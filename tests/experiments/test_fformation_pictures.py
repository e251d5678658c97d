from __future__ import annotations

import csv
import math

import cv2

from costmap.render import PERSON
from sid.experiments.fformation import LabelledFrame
from sid.experiments.fformation_pictures import (
    FALSE_GROUP,
    OUTCOME_COLOURS,
    error_frames,
    frame_picture,
    write_error_pictures,
)
from sid.perception.people import Person

PAIR = [Person(1, 1.0, 0.0, 0.0), Person(2, 1.8, 0.0, math.pi)]
LONERS = [Person(3, 4.0, 3.0, None), Person(4, 5.0, 0.0, math.pi / 2)]


def frame(stamp: float, truth: list[set[int]]) -> LabelledFrame:
    return LabelledFrame("seq", float(stamp), [*PAIR, *LONERS], [frozenset(t) for t in truth])


def test_frames_with_errors_come_worst_first_and_clean_frames_not_at_all():
    frames = [
        frame(1, [{1, 2}]),  # exact: clean
        frame(2, [{1, 2}, {3, 4}]),  # one exact, one missed: F1 at T = 1 of 2/3
        frame(3, [{1, 2, 3}]),  # all but one: lacking, F1 0
        frame(4, [{1, 2}]),  # exact, and a false group
    ]
    found = [[(1, 2)], [(1, 2)], [(1, 2)], [(1, 2), (3, 4)]]
    worst = error_frames("Set", frames, found, [2 / 3, 1.0])
    assert [(e.position, e.frame.timestamp) for e in worst] == [(2, 3), (1, 2), (3, 4)]
    assert worst[0].outcomes == {frozenset({1, 2, 3}): "lacking"} and worst[0].counts() == {"lacking": 1}
    assert worst[1].counts() == {"missed": 1} and worst[1].scores == {"2/3": (1.0, 0.5), "1": (1.0, 0.5)}
    assert worst[2].false_groups == [frozenset({3, 4})] and worst[2].counts() == {"false_groups": 1}


def test_a_picture_colours_true_groups_by_how_they_came_out():
    (errors,) = error_frames("Set", [frame(2, [{1, 2}, {3, 4}])], [[(1, 2), (3, 4, 5)]], [2 / 3])
    assert errors.outcomes == {frozenset({1, 2}): "exact", frozenset({3, 4}): "one_too_many"}
    img = frame_picture(errors, "Set, t = 2")
    assert img.ndim == 3 and 400 < img.shape[0] < 2000 and 600 < img.shape[1] < 2500
    colours = {tuple(int(c) for c in px) for px in img.reshape(-1, 3)}
    assert OUTCOME_COLOURS["exact"] in colours and OUTCOME_COLOURS["one_too_many"] in colours
    (missed,) = error_frames("Set", [frame(2, [{1, 2}])], [[(3, 4)]], [2 / 3])
    colours = {tuple(int(c) for c in px) for px in frame_picture(missed, "t").reshape(-1, 3)}
    assert OUTCOME_COLOURS["missed"] in colours and FALSE_GROUP in colours and PERSON in colours


def test_the_pictures_and_their_index_are_written_for_the_worst_frames_up_to_the_cap(tmp_path):
    frames = [frame(1, [{1, 2}]), frame(2, [{1, 2}, {3, 4}]), frame(3, [{1, 2, 3}])]
    found = [[(1, 2)], [(1, 2)], [(1, 2)]]
    written, counts = write_error_pictures({"Set": frames}, {"Set": found}, tmp_path, 1, [2 / 3, 1.0], "ospace")
    assert [p.name for p in written] == ["frame_Set_1.png", "index.csv"] and counts == {"Set": (2, 1)}
    assert cv2.imread(str(written[0])) is not None
    with open(tmp_path / "index.csv", newline="") as index:
        rows = list(csv.DictReader(index))
    assert rows == [
        {"dataset": "Set", "rank": "1", "frame": "2", "sequence": "seq", "timestamp": "3",
         "precision T=2/3": "1.000", "recall T=2/3": "1.000", "precision T=1": "0.000", "recall T=1": "0.000",
         "errors": "lacking 1", "file": "frame_Set_1.png"}
    ]  # fmt: skip


def test_a_true_group_absent_from_the_frame_is_named_in_the_legend(legend):
    seen = legend
    (errors,) = error_frames("Set", [frame(1, [{8, 9}, {1, 7}])], [[]], [2 / 3])
    frame_picture(errors, "t")
    assert "true group 8, 9: not in the frame" in seen[-1] and "true group 1, 7: 7 not in the frame" in seen[-1]
    assert "unknown facing: id?" in seen[-1]  # person 3
