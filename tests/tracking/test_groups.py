"""GroupTracker on tracked people generated here (metres, radians, seconds)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from sid.tracking import GroupTracker, GroupTrackerParams, TrackedPerson, TrackingError

DT = 1 / 15


def _person(
    track_id: int, x: float, y: float, theta: float | None, v: tuple[float, float] = (0.0, 0.0)
) -> TrackedPerson:
    state = "walking" if math.hypot(*v) > 0.5 else "standing"
    return TrackedPerson(
        track_id, x, y, v[0], v[1], theta, state, True, True, 0.0, None, 0.1, 0.0 if theta is None else 1.0
    )


def _circle(ids: tuple[int, ...] = (1, 2, 3), centre: tuple[float, float] = (3.0, 0.0), r: float = 0.7):
    """People on a circle facing its centre."""
    out = []
    for k, track_id in enumerate(ids):
        a = 2 * math.pi * k / len(ids) + 0.3
        x, y = centre[0] + r * math.cos(a), centre[1] + r * math.sin(a)
        out.append(_person(track_id, x, y, math.atan2(centre[1] - y, centre[0] - x)))
    return out


def test_a_conversation_appears_after_n_of_m_frames_and_keeps_its_id() -> None:
    tracker = GroupTracker(GroupTrackerParams(confirm_hits=3, confirm_window=5))
    reported = [tracker.update(_circle(), k * DT) for k in range(30)]
    assert [len(r) for r in reported[:4]] == [0, 0, 1, 1]
    ids = {g.id for frame in reported for g in frame}
    assert len(ids) == 1
    group = reported[-1][0]
    assert group.kind == "conversation" and group.members == (1, 2, 3)
    assert group.interest_point == pytest.approx((3.0, 0.0), abs=0.05)
    assert len(group.zone) >= 1


def test_a_group_survives_short_misses_and_ends_after_the_timeout() -> None:
    tracker = GroupTracker(GroupTrackerParams(miss_timeout=0.5))
    for k in range(5):
        groups = tracker.update(_circle(), k * DT)
    (group,) = groups
    t = 4 * DT
    blind = [_person(p.id, p.x, p.y, None) for p in _circle()]  # no facings: the detector finds no group
    for k in range(1, 8):  # 0.47 s
        (still,) = tracker.update(blind, t + k * DT)
        assert still.id == group.id and still.members == group.members and still.last_seen == t
    (back,) = tracker.update(_circle(), t + 8 * DT)
    assert back.id == group.id
    t += 8 * DT
    alive = [tracker.update(blind, t + k * DT) for k in range(1, 12)]
    assert alive[6] and not alive[8]  # 0.47 s kept, 0.6 s gone


def test_a_member_who_walks_away_leaves_at_once() -> None:
    tracker = GroupTracker()
    for k in range(5):
        tracker.update(_circle((1, 2, 3, 4)), k * DT)
    people = _circle((1, 2, 3, 4))
    leaving = people[3]
    people[3] = _person(4, leaving.x + 0.3, leaving.y, 0.0, (1.2, 0.0))
    (group,) = tracker.update(people, 5 * DT)
    assert group.members == (1, 2, 3)
    people[3] = _person(4, leaving.x + 3.0, leaving.y, 0.0)  # far away, standing again
    (group,) = tracker.update(people, 6 * DT)
    assert 4 not in group.members


def test_a_member_who_drifts_beyond_the_leave_distance_leaves_while_the_group_is_missed() -> None:
    tracker = GroupTracker(GroupTrackerParams(leave_distance=1.5))
    for k in range(5):
        tracker.update(_circle((1, 2, 3, 4)), k * DT)
    people = [_person(p.id, p.x, p.y, None) for p in _circle((1, 2, 3, 4))]
    people[0] = _person(1, 6.0, 0.0, None)
    (group,) = tracker.update(people, 5 * DT)
    assert group.members == (2, 3, 4)


@pytest.mark.parametrize("layout", ["side_by_side", "in_file"])
def test_people_walking_together_are_never_a_conversation(layout: str) -> None:
    tracker = GroupTracker()
    v = (1.2, 0.0)
    for k in range(30):
        x = 1.0 + 1.2 * k * DT
        if layout == "side_by_side":  # facing each other while they walk: rays meet, still not an o-space
            people = [_person(1, x, 0.4, -math.pi / 2, v), _person(2, x, -0.4, math.pi / 2, v)]
        else:
            people = [_person(1, x, 0.0, 0.0, v), _person(2, x - 1.2, 0.0, 0.0, v)]
        groups = tracker.update(people, k * DT)
        assert all(g.kind == "walking" for g in groups)
    (group,) = groups
    assert group.members == (1, 2) and group.zone.shape == (0, 2)
    assert group.velocity == pytest.approx(v)
    assert group.interest_point[0] == pytest.approx(x - (0.6 if layout == "in_file" else 0.0))


def test_walkers_at_different_velocities_are_no_group() -> None:
    tracker = GroupTracker()
    for k in range(10):
        people = [_person(1, 1.0 + 1.2 * k * DT, 0.0, 0.0, (1.2, 0.0)), _person(2, 2.0, -1.0, 1.6, (0.0, 1.2))]
        assert tracker.update(people, k * DT) == []


def test_group_ids_are_never_reused() -> None:
    tracker = GroupTracker(GroupTrackerParams(miss_timeout=0.0))
    for k in range(5):
        groups = tracker.update(_circle(), k * DT)
    (first,) = groups
    assert tracker.update([], 5 * DT) == []
    for k in range(6, 11):
        groups = tracker.update(_circle(), k * DT)
    assert groups[0].id > first.id


def test_bad_input_is_refused() -> None:
    with pytest.raises(ValueError, match="appears twice"):
        GroupTracker().update([_person(1, 1.0, 0.0, 0.0), _person(1, 2.0, 0.0, 0.0)], 0.0)
    with pytest.raises(ValueError, match="confirm_hits"):
        GroupTrackerParams(confirm_hits=6, confirm_window=5)
    with pytest.raises(ValueError, match="walk_confirm_hits"):
        GroupTrackerParams(walk_confirm_hits=6, confirm_window=5)
    with pytest.raises(ValueError, match="walk_confirm_hits"):
        GroupTrackerParams(walk_confirm_hits=0)
    with pytest.raises(ValueError, match="min_overlap"):
        GroupTrackerParams(min_overlap=0.0)


def test_noisy_tracks_keep_one_group() -> None:
    rng = np.random.default_rng(1)
    tracker = GroupTracker()
    ids = set()
    for k in range(60):
        people = [
            _person(p.id, p.x + rng.normal(0, 0.03), p.y + rng.normal(0, 0.03), p.theta + rng.normal(0, 0.1))
            for p in _circle()
            if p.theta is not None
        ]
        ids |= {g.id for g in tracker.update(people, k * DT)}
    assert len(ids) == 1


def test_tracks_whose_velocity_is_not_yet_known_join_no_conversation() -> None:
    tracker = GroupTracker(GroupTrackerParams(max_speed_sigma=0.4))
    young = [
        TrackedPerson(
            p.id, p.x, p.y, 0.0, 0.0, p.theta, "standing", True, True, 0.0, None, 0.9, 0.0 if p.theta is None else 1.0
        )
        for p in _circle()
    ]
    for k in range(10):
        assert tracker.update(young, k * DT) == []


def test_a_member_missed_for_a_moment_stays_and_one_who_joins_another_group_moves() -> None:
    tracker = GroupTracker(GroupTrackerParams(miss_timeout=0.5))
    for k in range(5):
        tracker.update(_circle((1, 2, 3, 4)), k * DT)
    people = _circle((1, 2, 3, 4))
    people[3] = _person(4, people[3].x, people[3].y, None)  # no facing for a moment: not found with the group
    (group,) = tracker.update(people, 5 * DT)
    assert group.members == (1, 2, 3, 4)
    far = _circle((4, 5), centre=(3.0, 4.0), r=0.5)  # 4 now talks with 5, 4 m away
    for k in range(6, 12):
        groups = tracker.update(_circle((1, 2, 3)) + far, k * DT)
    assert sorted(g.members for g in groups) == [(1, 2, 3), (4, 5)]


def test_walkers_moving_together_are_a_group_through_noisy_velocity_estimates() -> None:
    # The filtered velocities differ by 0.6 m/s (above walk_velocity_difference) in alternate frames, as a young
    # track's do, but the pair's relative position holds: over the walk window they move apart at 0 m/s.
    tracker = GroupTracker(GroupTrackerParams(walk_window=2.0, walk_velocity_difference=0.4))
    found = []
    for k in range(40):
        x, wobble = 1.0 + 1.2 * k * DT, 0.3 if k % 2 else -0.3
        people = [_person(1, x, 0.3, 0.0, (1.2 + wobble, 0.0)), _person(2, x, -0.3, 0.0, (1.2 - wobble, 0.0))]
        found.append([g.members for g in tracker.update(people, k * DT)])
    assert all(groups == [(1, 2)] for groups in found[20:])  # once the window is filled (1 s of history)


@pytest.mark.parametrize("window", [0.0, 1e-7, 0.1])
def test_a_walk_window_of_no_length_judges_walkers_by_their_velocities(window: float) -> None:
    # With no window to look back over (0, or shorter than the trackers' time tolerance), only the current frame is
    # in it: it gives no displacement rate (0 / 0 s), so the velocities decide, as for a pair with too little history.
    tracker = GroupTracker(GroupTrackerParams(walk_window=window))
    for k in range(30):
        x = 1.0 + 1.0 * k * DT
        people = [_person(1, x, 0.3, 0.0, (1.0, 0.0)), _person(2, x, -0.3, 0.0, (1.0, 0.0))]
        groups = tracker.update(people, k * DT)
    assert [(g.kind, g.members) for g in groups] == [("walking", (1, 2))]


def test_walkers_who_drift_apart_are_no_group_even_when_their_velocities_look_alike() -> None:
    # Each frame's velocities are equal but the positions spread at 0.6 m/s: the displacement over the window counts.
    tracker = GroupTracker(GroupTrackerParams(walk_window=2.0, walk_distance=3.0, walk_velocity_difference=0.4))
    for k in range(40):
        x, spread = 1.0 + 1.2 * k * DT, 0.3 * k * DT
        people = [_person(1, x, 0.3 + spread, 0.0, (1.2, 0.0)), _person(2, x, -0.3 - spread, 0.0, (1.2, 0.0))]
        groups = tracker.update(people, k * DT)
    assert groups == []


def test_walkers_closing_in_become_a_group_only_once_close_for_the_whole_walk_window() -> None:
    # Two walkers abreast at 1.2 m/s, the second closing in sideways at 0.5 m/s (below walk_velocity_difference) from
    # 2.6 m to 0.8 m apart, reached at t = 3.6 s. They come within walk_distance (1.5 m) at t = 2.2 s, but were
    # farther apart within the last walk_window (2 s) until t = 4.2 s: a stranger passing close is not yet a group.
    tracker = GroupTracker(GroupTrackerParams(walk_window=2.0, walk_distance=1.5, walk_velocity_difference=0.8))
    found = {}
    for k in range(int(6.0 / DT)):
        t = k * DT
        gap = max(2.6 - 0.5 * t, 0.8)
        lateral = 0.5 if gap > 0.8 else 0.0
        people = [_person(1, 1.2 * t, 0.4, 0.0, (1.2, 0.0)), _person(2, 1.2 * t, 0.4 - gap, 0.0, (1.2, lateral))]
        found[round(t, 3)] = [g.members for g in tracker.update(people, t)]
    assert all(groups == [] for t, groups in found.items() if t <= 4.1)
    assert all(groups == [(1, 2)] for t, groups in found.items() if t >= 4.6)


@pytest.mark.parametrize(("dt", "frames_to_report"), [(1 / 15, 3), (0.4, 2)])
def test_a_slow_detector_reports_a_group_found_twice_in_a_row_confirm_time_apart(
    dt: float, frames_to_report: int
) -> None:
    params = GroupTrackerParams(confirm_hits=3, walk_confirm_hits=3, confirm_window=5, confirm_time=0.2)
    tracker = GroupTracker(params)
    v = (1.2, 0.0)
    reported = []
    for k in range(4):
        x = 1.0 + 1.2 * k * dt
        people = [_person(1, x, 0.3, 0.0, v), _person(2, x, -0.3, 0.0, v)]
        reported.append(bool(tracker.update(people, k * dt)))
    assert reported == [k + 1 >= frames_to_report for k in range(4)]


def test_a_walking_group_is_reported_when_first_found_and_a_conversation_after_three_frames() -> None:
    # The walking rule already looks back walk_window (close all along, moving alike): no frame count on top.
    tracker = GroupTracker()
    v = (1.2, 0.0)
    walkers = [[_person(1, 1.2 * k * DT, 5.3, 0.0, v), _person(2, 1.2 * k * DT, 4.7, 0.0, v)] for k in range(3)]
    reported = [tracker.update(walkers[k] + _circle((3, 4, 5)), k * DT) for k in range(3)]
    assert [sorted(g.kind for g in frame) for frame in reported] == [
        ["walking"],
        ["walking"],
        ["conversation", "walking"],
    ]
    assert len({g.id for frame in reported for g in frame if g.kind == "walking"}) == 1


def test_young_tracks_moving_together_are_a_walking_group_before_the_tracker_calls_them_walking() -> None:
    """The tracker's state says standing while a new track's speed is uncertain; moving_speed does not wait."""
    v = (0.9, 0.0)

    def pair(k: int) -> list[TrackedPerson]:
        x = 1.0 + v[0] * k * DT
        return [dataclasses.replace(_person(i, x, y, None, v), state="standing") for i, y in ((1, 0.35), (2, -0.35))]

    early = GroupTracker()
    groups = [early.update(pair(k), k * DT) for k in range(6)]
    assert groups[-1] and groups[-1][0].kind == "walking" and groups[-1][0].members == (1, 2)
    waiting = GroupTracker(GroupTrackerParams(moving_speed=1.0))  # only the tracker's walking state counts
    assert all(waiting.update(pair(k), k * DT) == [] for k in range(6))


def _first_report_of_a_pair_far_apart_exactly_one_window_ago(offset: float, dt: float) -> int:
    """The frame at which two walkers are first reported together: 1.6 m apart in their first frame (beyond
    walk_distance), 1 m apart from then on, fed every ``dt`` seconds at the clock times ``offset + k dt`` from k = 7
    on (as a replay at a camera's rate computes them)."""
    tracker = GroupTracker(GroupTrackerParams(walk_window=2.0, walk_distance=1.5))
    v = (1.2, 0.0)
    for k in range(7, 7 + int(4.0 / dt)):
        x, gap = 1.2 * k * dt, 1.6 if k == 7 else 1.0
        people = [_person(1, x, 0.0, 0.0, v), _person(2, x, -gap, 0.0, v)]
        if tracker.update(people, offset + k * dt):
            return k
    raise AssertionError("never reported")


@pytest.mark.parametrize("dt", [1 / 15, 0.4])
def test_groups_do_not_depend_on_the_clocks_offset(dt: float) -> None:
    """The first frame is walk_window before a later one: whether it is still in the window (and which frames are
    looked at 0.2 s apart) must not depend on how rounding treats the clock's times, e.g. ROS stamps in seconds since
    1970."""
    frames = {offset: _first_report_of_a_pair_far_apart_exactly_one_window_ago(offset, dt)
              for offset in (0.0, 0.1, 17.3, 1234.567, 1.7e9 + 0.123, 1.7e9 + 0.9)}  # fmt: skip
    assert len(set(frames.values())) == 1, frames


@pytest.mark.parametrize("back", [0.0, 2 * DT])
def test_a_frame_not_after_the_last_is_refused_naming_both_timestamps_and_changes_nothing(back) -> None:
    tracker = GroupTracker(GroupTrackerParams(miss_timeout=0.5))
    for k in range(5):
        groups = tracker.update(_circle(), 4 * DT + k * DT)
    (group,) = groups
    last = 8 * DT
    with pytest.raises(TrackingError, match=rf"timestamp {4 * DT + back} s is not after the last one, {last} s"):
        tracker.update([], 4 * DT + back)  # with a time gone backwards the group would never time out
    blind = [_person(p.id, p.x, p.y, None) for p in _circle()]
    alive = [tracker.update(blind, last + k * DT) for k in range(1, 10)]
    assert [g.id for g in alive[6]] == [group.id]
    assert not alive[8]  # gone after miss_timeout, counted from the last good frame
