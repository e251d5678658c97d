import math

import numpy as np
import pytest

from sid.experiments.simulate.follower import FollowerParams, follow, nearest_arc_length, point_at, remaining

PARAMS = FollowerParams(max_speed=0.5, max_turn_rate=1.0)


def test_straight_ahead_drives_at_full_speed():
    command = follow(np.array([[0.0, 0.0], [5.0, 0.0]]), (0.0, 0.0, 0.0), 0.5, PARAMS)
    assert command.linear == pytest.approx(0.5)
    assert command.angular == pytest.approx(0.0)
    assert command.carrot == pytest.approx((0.75, 0.0))  # lookahead 1.5 s x 0.5 m/s


def test_a_path_to_the_left_turns_left_on_the_pure_pursuit_arc():
    command = follow(np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 5.0]]), (0.0, 0.0, 0.0), 0.0, PARAMS)
    ahead, left = command.carrot
    assert left > 0 and command.angular > 0
    assert command.angular / command.linear == pytest.approx(2 * left / (ahead**2 + left**2))


def test_a_carrot_behind_turns_in_place():
    command = follow(np.array([[0.0, 0.0], [-3.0, 0.1]]), (0.0, 0.0, 0.0), 0.0, PARAMS)
    assert command.linear == 0.0
    assert command.angular == pytest.approx(1.0)  # towards the carrot, at the turn-rate limit


def test_speed_drops_on_tight_arcs_and_near_the_goal():
    straight = follow(np.array([[0.0, 0.0], [5.0, 0.0]]), (0.0, 0.0, 0.0), 0.5, PARAMS)
    tight = follow(np.array([[0.0, 0.0], [0.3, 0.3]]), (0.0, 0.0, 0.0), 0.0, PARAMS)
    near = follow(np.array([[0.0, 0.0], [0.2, 0.0]]), (0.0, 0.0, 0.0), 0.5, PARAMS)
    assert tight.linear < straight.linear
    assert abs(tight.angular) <= PARAMS.max_turn_rate + 1e-12
    assert near.linear == pytest.approx(0.5 * 0.2 / PARAMS.approach_distance_m)


def test_following_a_corner_reaches_its_end():
    path = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 3.0]])
    x, y, yaw, v, dt = 0.0, 0.0, 0.0, 0.0, 0.1
    for _ in range(400):
        command = follow(path, (x, y, yaw), v, PARAMS)
        v = command.linear
        x, y, yaw = x + v * dt * math.cos(yaw), y + v * dt * math.sin(yaw), yaw + command.angular * dt
        if math.hypot(x - 3.0, y - 3.0) < 0.1:
            break
    assert math.hypot(x - 3.0, y - 3.0) < 0.1
    assert nearest_arc_length(path, (x, y))[0] > 5.8


def test_path_geometry_helpers():
    path = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]])
    assert nearest_arc_length(path, (1.0, 0.5)) == pytest.approx((1.0, 0.5))
    assert point_at(path, 3.0) == pytest.approx([2.0, 1.0])
    assert point_at(path, 10.0) == pytest.approx([2.0, 2.0])
    rest = remaining(path, (1.0, 0.5), skip=0.5)
    np.testing.assert_allclose(rest, [[1.5, 0.0], [2.0, 0.0], [2.0, 2.0]])


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="at least one finite"):
        follow(np.zeros((0, 2)), (0.0, 0.0, 0.0), 0.0)
    with pytest.raises(ValueError, match="max_lookahead_m"):
        FollowerParams(min_lookahead_m=1.0, max_lookahead_m=0.5)
