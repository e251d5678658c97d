"""The simulated robot: a differential-drive base (unicycle kinematics) with speed, turn-rate and acceleration limits.

State: pose of ``base_footprint`` in the map (x, y in metres, yaw in radians, REP-105) and the current linear (m/s)
and angular (rad/s) velocities. Each step clamps the commanded velocities to the limits, moves them towards the
command by at most the acceleration limits times the step, and integrates the exact arc over the step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sid.checks import check_number, check_numbers

__all__ = ["DriveLimits", "RobotState", "step"]


@dataclass(frozen=True)
class DriveLimits:
    """Limits of the base: radius of its disc footprint (m), top speed (m/s, forward only), top turn rate (rad/s),
    linear (m/s^2) and angular (rad/s^2) acceleration."""

    radius: float = 0.25
    max_speed: float = 0.5
    max_turn_rate: float = 1.5
    max_accel: float = 1.0
    max_angular_accel: float = 3.0

    def __post_init__(self) -> None:
        check_numbers("robot", self, ("radius", "max_speed", "max_turn_rate", "max_accel", "max_angular_accel"),
                      low=0, low_open=True)  # fmt: skip


@dataclass(frozen=True)
class RobotState:
    """Pose in the map (m, m, rad) and velocities (m/s, rad/s)."""

    x: float
    y: float
    yaw: float
    v: float = 0.0
    w: float = 0.0

    @property
    def pose(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.yaw)


def _towards(current: float, target: float, step: float) -> float:
    return current + max(-step, min(step, target - current))


def step(state: RobotState, linear: float, angular: float, dt: float, limits: DriveLimits) -> RobotState:
    """The state ``dt`` seconds later under the command (linear m/s, angular rad/s), limits applied."""
    check_number("robot step", "dt", dt, low=0, low_open=True, unit="seconds")
    v_cmd = max(0.0, min(limits.max_speed, linear))
    w_cmd = max(-limits.max_turn_rate, min(limits.max_turn_rate, angular))
    v = _towards(state.v, v_cmd, limits.max_accel * dt)
    w = _towards(state.w, w_cmd, limits.max_angular_accel * dt)
    if abs(w) < 1e-9:
        x = state.x + v * dt * math.cos(state.yaw)
        y = state.y + v * dt * math.sin(state.yaw)
    else:
        radius = v / w
        yaw1 = state.yaw + w * dt
        x = state.x + radius * (math.sin(yaw1) - math.sin(state.yaw))
        y = state.y - radius * (math.cos(yaw1) - math.cos(state.yaw))
    return RobotState(x, y, math.remainder(state.yaw + w * dt, math.tau), v, w)
