"""Scripted motion: standing, waiting, walking along waypoints, arriving; and the checks of its numbers."""

from __future__ import annotations

import math

import pytest

from sid.scenario.motion import Trajectory


def test_a_walker_waits_walks_each_leg_and_stands_at_the_end() -> None:
    walk = Trajectory(0.0, 0.0, 2.0, ((3.0, 0.0), (3.0, 4.0)), speed=1.0, start_time=2.0)
    assert walk.duration == pytest.approx(7.0) and walk.end_time == pytest.approx(9.0)
    waiting = walk.at(1.0)
    assert (waiting.x, waiting.y, waiting.yaw, waiting.moving) == (0.0, 0.0, 2.0, False)
    first = walk.at(3.5)  # 1.5 m along the first leg, facing +x
    assert (first.x, first.y, first.yaw) == pytest.approx((1.5, 0.0, 0.0))
    assert (first.vx, first.vy) == pytest.approx((1.0, 0.0)) and first.moving
    second = walk.at(7.0)  # 2 m up the second leg
    assert (second.x, second.y, second.yaw) == pytest.approx((3.0, 2.0, math.pi / 2))
    assert (second.vx, second.vy) == pytest.approx((0.0, 1.0))
    for t in (9.0, 30.0):  # arrived: stands at the last waypoint facing the last leg
        end = walk.at(t)
        assert (end.x, end.y, end.yaw, end.moving) == (3.0, 4.0, pytest.approx(math.pi / 2), False)


def test_standing_still_and_unknown_facing() -> None:
    still = Trajectory(1.0, 2.0, None)
    assert still.at(5.0).yaw is None and still.duration == 0 and still.end_time == 0
    walker = Trajectory(0.0, 0.0, None, ((0.0, -2.0),), start_time=1.0)  # no theta: faces its first leg
    assert walker.at(0.0).yaw == pytest.approx(-math.pi / 2)
    assert walker.at(1.0 + 1.0 / 1.2).y == pytest.approx(-1.0)  # default speed 1.2 m/s


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"speed": 0.0}, "speed must be a positive number"),
        ({"speed": math.nan}, "speed"),
        ({"start_time": -1.0}, "start_time must be a finite number of seconds >= 0"),
        ({"path": ((1.0, math.nan),)}, r"path\[0\]\[1\]"),
        ({"path": ((0.0, 0.0),)}, r"path\[0\] \(0.0, 0.0\) repeats the point before it"),
        ({"path": ((1.0, 0.0, 2.0),)}, "pair"),
    ],
)
def test_bad_numbers_name_the_field(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        Trajectory(0.0, 0.0, 0.0, **({"path": ((1.0, 0.0),)} | kwargs))
