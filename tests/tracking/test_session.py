"""TrackingSession over per-frame results: time order, and what a refused result leaves."""

from __future__ import annotations

import math

import pytest

from sid.perception.people import Person
from sid.perception.pipeline import FrameResult
from sid.tracking import TrackingError, TrackingSession


def _result(frame: int, timestamp: float, people: list[Person]) -> FrameResult:
    return FrameResult(frame, timestamp, [], people, [])


def test_a_result_with_bad_people_is_refused_and_leaves_the_session_as_it_was() -> None:
    session = TrackingSession()
    for k in range(3):
        session.update(_result(k, k * 0.1, [Person(0, 2.0, 0.0, 0.0)]))
    with pytest.raises(TrackingError, match="person 0: x must be a finite number"):
        session.update(_result(3, 1.0, [Person(0, math.nan, 0.0, 0.0)]))
    update = session.update(_result(4, 0.3, [Person(0, 2.0, 0.0, 0.0)]))  # after the last good one
    assert [p.id for p in update.people] == [1]
    assert update.people[0].last_seen == 0.3
