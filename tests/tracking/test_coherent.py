"""CoherentMotion, the walking-group reference, on tracks generated here (ground frame, metres, 2.5 Hz)."""

from __future__ import annotations

import pytest

from sid.tracking import TrackedPerson, TrackingError
from sid.tracking.coherent import CoherentMotion, CoherentMotionParams

DT = 0.4


def _track(track_id: int, x: float, y: float, vx: float, vy: float) -> TrackedPerson:
    state = "walking" if abs(vx) + abs(vy) > 0.5 else "standing"
    return TrackedPerson(track_id, x, y, vx, vy, None, state, True, True, 0.0, None, 0.1, 0.0)


def _frames(reference: CoherentMotion, count: int, start: int = 0) -> list[list[frozenset[int]]]:
    """A pair (1, 2) 0.6 m apart at 1.2 m/s, 3 walking the other way 1 m beside them, 4 standing 5 m away."""
    out = []
    for k in range(start, start + count):
        x = 1.2 * DT * k
        people = [_track(1, x, 0.0, 1.2, 0.0), _track(2, x, 0.6, 1.2, 0.0), _track(3, 10 - x, 1.6, -1.2, 0.0)]
        people.append(_track(4, 5.0, -5.0, 0.0, 0.0))
        out.append(reference.update(people, k * DT))
    return out


def test_a_pair_walking_together_is_a_group_once_it_held_long_enough() -> None:
    reference = CoherentMotion(CoherentMotionParams(min_frames=3))
    groups = _frames(reference, 8)
    assert groups[:2] == [[], []]  # two frames together are not yet three
    assert all(g == [frozenset({1, 2})] for g in groups[2:])  # never 3 (opposite velocity) or 4 (too far)


def test_people_who_part_stop_being_a_group_after_the_window() -> None:
    reference = CoherentMotion(CoherentMotionParams(window=2.0, share=0.8))
    _frames(reference, 6)
    apart = []
    for k in range(6, 16):
        people = [_track(1, 1.2 * DT * k, 0.0, 1.2, 0.0), _track(2, 3.0, 4.0, 0.0, 1.2)]  # 2 turned away, far off
        apart.append(reference.update(people, k * DT))
    assert apart[0] == [frozenset({1, 2})]  # 5 of the last 6 frames still coherent: 0.83 >= share
    assert apart[-1] == []


def test_reset_forgets_the_history() -> None:
    reference = CoherentMotion()
    _frames(reference, 6)
    reference.reset()
    assert _frames(reference, 1, start=6) == [[]]


@pytest.mark.parametrize(
    ("field", "value", "problem"),
    [("distance", 0.0, "distance"), ("share", 1.5, "share"), ("min_frames", 0, "min_frames"), ("window", -1, "window")],
)
def test_bad_parameters_are_refused(field: str, value: float, problem: str) -> None:
    with pytest.raises(ValueError, match=f"coherent motion: {problem}"):
        CoherentMotionParams(**{field: value})


def _first_report_after_a_frame_apart_exactly_one_window_ago(offset: float, dt: float) -> int:
    """The frame at which two walkers are first a group: 3 m apart in their first frame, 0.6 m apart from then on,
    fed every ``dt`` seconds at the clock times ``offset + k dt`` from k = 7 on (as a replay computes them); every
    frame in the window must be coherent (share 1)."""
    reference = CoherentMotion(CoherentMotionParams(window=2.0, share=1.0, min_frames=1))
    for k in range(7, 7 + int(4.0 / dt)):
        x, gap = 1.2 * k * dt, 3.0 if k == 7 else 0.6
        if reference.update([_track(1, x, 0.0, 1.2, 0.0), _track(2, x, gap, 1.2, 0.0)], offset + k * dt):
            return k
    raise AssertionError("never a group")


@pytest.mark.parametrize("dt", [1 / 15, 0.4])
def test_groups_do_not_depend_on_the_clocks_offset(dt: float) -> None:
    """Whether a frame exactly one window old still counts must not depend on how rounding treats the clock's times
    (ROS stamps in seconds since 1970): the trackers' TIME_TOLERANCE, as in GroupTracker."""
    frames = {offset: _first_report_after_a_frame_apart_exactly_one_window_ago(offset, dt)
              for offset in (0.0, 0.1, 17.3, 1234.567, 1.7e9 + 0.123, 1.7e9 + 0.9)}  # fmt: skip
    assert len(set(frames.values())) == 1, frames


def test_a_frame_not_after_the_last_is_refused_and_counts_nothing() -> None:
    reference = CoherentMotion(CoherentMotionParams(min_frames=3))
    assert _frames(reference, 2) == [[], []]
    for repeated in (DT, 0.0):  # a repeated frame would count twice towards min_frames
        with pytest.raises(TrackingError, match=f"timestamp {repeated} s is not after the last one, {DT} s"):
            _frames(reference, 1, start=round(repeated / DT))
    assert _frames(reference, 1, start=2) == [[frozenset({1, 2})]]  # the third frame, as without the refusals
