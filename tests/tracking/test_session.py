"""TrackingSession over per-frame results: time order, and what a refused result leaves."""

from __future__ import annotations

import math

import pytest

from sid.perception.people import Person
from sid.perception.pipeline import FrameResult
from sid.perception.robot_pose import RobotPose
from sid.tracking import TrackedPerson, TrackingError, TrackingParams, TrackingSession
from sid.tracking.session import SessionUpdate, split_reported
from sid.tracking.tracker import TimeGapWarning


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


@pytest.mark.parametrize("jump", [RobotPose(5.0, 0.0, 0.0), None], ids=["pose jump", "frame change"])
def test_a_result_with_bad_people_that_would_reset_the_trackers_leaves_them_as_they_were(
    jump: RobotPose | None,
) -> None:
    # The reset (a pose jump, or positions in another frame) ran before the people were checked: the refused result
    # had already made the session forget its tracks, and the person came back under a new id.
    session = TrackingSession()
    for k in range(3):
        session.update(
            FrameResult(k, k * 0.1, [], [Person(0, 2.0, 0.0, 0.0)], [], frame_id="map", robot_pose=RobotPose(0, 0, 0))
        )
    bad = [Person(0, 2.0, 0.0, 0.0), Person(0, 3.0, 0.0, 0.0)]
    frame_id = "map" if jump else "base_footprint"
    with pytest.raises(TrackingError, match="person id 0 appears twice"):
        session.update(FrameResult(3, 0.3, [], bad, [], frame_id=frame_id, robot_pose=jump))
    good = FrameResult(4, 0.4, [], [Person(0, 2.0, 0.0, 0.0)], [], frame_id="map", robot_pose=RobotPose(0, 0, 0))
    update = session.update(good)
    assert update.reset is None and [p.id for p in update.people] == [1]


def test_time_going_back_more_than_max_time_back_starts_the_trackers_over() -> None:
    """One frame stamped in milliseconds among frames in seconds (or a looped recording): every later frame was
    refused as out of time order, for good. Time going back more than max_time_back now resets both trackers, with a
    reason; going back less is refused as before, in ``update`` and in ``track`` alike."""
    for feed in ("update", "track"):
        session = TrackingSession()

        def step(timestamp: float, session: TrackingSession = session, feed: str = feed) -> SessionUpdate:
            people = [Person(0, 2.0, 0.0, 0.0), Person(1, 2.0, 1.0, math.pi)]
            if feed == "update":
                return session.update(_result(0, timestamp, people))
            return session.track(people, timestamp)

        for k in range(3):
            assert step(1.7e9 + 0.1 * k).reset is None
        with pytest.warns(TimeGapWarning):
            step(1.7e12)  # the glitch: a gap that ends the tracks
        with pytest.raises(TrackingError, match="out of time order"):
            step(1.7e12 - 0.5)  # within max_time_back: a late frame, refused
        update = step(1.7e9 + 0.3)
        assert update.reset == "time went back 1.7e+12 s" and update.people == []
        ids = {p.id for k in range(4, 8) for p in step(1.7e9 + 0.1 * k).people}
        assert len(ids) == 2  # tracked again


def test_a_missed_member_of_a_group_stays_reported_while_a_lone_one_is_held() -> None:
    """Held: a confirmed track missed in the camera's view for longer than report_timeout, kept for re-association
    but not reported; a member of a confirmed group is reported while its group holds it."""
    session = TrackingSession(TrackingParams(report_timeout=0.3))
    pair = [Person(0, 2.0, 0.4, -math.pi / 2), Person(1, 2.0, -0.4, math.pi / 2)]
    lone = Person(2, 6.0, 3.0, 0.0)
    for k in range(10):
        update = session.track([*pair, lone], 0.1 * k)
    assert len(update.groups) == 1 and len(update.people) == 3
    ids = {p.id for p in update.people}
    for k in range(10, 15):  # one member and the lone person missed for 0.5 s
        update = session.track(pair[:1], 0.1 * k)
    (group,) = update.groups
    assert {p.id for p in update.people} == set(group.members) and len(group.members) == 2
    (held,) = update.held
    assert held.id in ids - set(group.members) and held.missed_in_view == pytest.approx(0.5)
    assert {p.id for p in update.people} | {held.id} == ids


def test_split_reported_keeps_the_order_and_a_group_while_one_member_is_fresh() -> None:
    tracks = [TrackedPerson(i, 0.0, 0.0, 0.0, 0.0, None, "standing", False, True, 0.0, None, 0.1, 0.0, missed)
              for i, missed in ((1, 0.4), (2, 0.5), (3, 0.0), (4, 2.0), (5, 0.9), (6, 1.0))]  # fmt: skip
    reported, held, kept = split_reported(tracks, [{3, 4}, {5, 6}], 0.4)
    assert [p.id for p in reported] == [1, 3, 4] and [p.id for p in held] == [2, 5, 6] and kept == [True, False]


def test_a_group_whose_members_all_went_unseen_is_held_with_them() -> None:
    """A pair that walked out of the detector's sight together: its tracks coast, held by nobody fresh."""
    session = TrackingSession(TrackingParams(report_timeout=0.3))
    pair = [Person(0, 2.0, 0.4, -math.pi / 2), Person(1, 2.0, -0.4, math.pi / 2)]
    for k in range(10):
        update = session.track(pair, 0.1 * k)
    (group,) = update.groups
    for k in range(10, 15):  # both missed for 0.5 s, in view
        update = session.track([], 0.1 * k)
    assert update.people == [] and update.groups == []
    assert [g.id for g in update.held_groups] == [group.id] and {p.id for p in update.held} == set(group.members)
    assert update.all_tracks().groups == tuple(update.held_groups)
