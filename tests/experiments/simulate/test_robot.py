import math

import pytest

from sid.experiments.simulate.robot import DriveLimits, RobotState, step

LIMITS = DriveLimits(max_speed=0.5, max_turn_rate=1.0, max_accel=10.0, max_angular_accel=10.0)


def test_straight_step_moves_along_heading():
    state = step(RobotState(1.0, 2.0, math.pi / 2, 0.5, 0.0), 0.5, 0.0, 0.2, LIMITS)
    assert (state.x, state.y) == pytest.approx((1.0, 2.1))
    assert state.yaw == pytest.approx(math.pi / 2)


def test_commands_are_clamped_to_the_limits():
    state = step(RobotState(0.0, 0.0, 0.0, 0.5, 1.0), 3.0, 5.0, 0.1, LIMITS)
    assert state.v == pytest.approx(0.5) and state.w == pytest.approx(1.0)
    backwards = step(RobotState(0.0, 0.0, 0.0), -1.0, 0.0, 0.1, LIMITS)
    assert backwards.v == 0.0 and backwards.x == 0.0


def test_acceleration_is_limited():
    slow = DriveLimits(max_accel=1.0, max_angular_accel=2.0)
    state = step(RobotState(0.0, 0.0, 0.0), 0.5, 1.5, 0.1, slow)
    assert state.v == pytest.approx(0.1) and state.w == pytest.approx(0.2)


def test_a_full_circle_of_arcs_comes_back():
    state = RobotState(0.0, 0.0, 0.0, 0.5, 1.0)
    steps = 100
    for _ in range(steps):
        state = step(state, 0.5, 1.0, 2 * math.pi / steps, LIMITS)
    assert (state.x, state.y) == pytest.approx((0.0, 0.0), abs=1e-9)
    # the circle has radius v / w = 0.5 m: halfway round it is 1 m to the left
    half = RobotState(0.0, 0.0, 0.0, 0.5, 1.0)
    for _ in range(steps // 2):
        half = step(half, 0.5, 1.0, 2 * math.pi / steps, LIMITS)
    assert (half.x, half.y) == pytest.approx((0.0, 1.0), abs=1e-9)


def test_bad_limits_and_steps_are_refused():
    with pytest.raises(ValueError, match="max_speed"):
        DriveLimits(max_speed=0.0)
    with pytest.raises(ValueError, match="dt"):
        step(RobotState(0.0, 0.0, 0.0), 0.1, 0.0, 0.0, LIMITS)
