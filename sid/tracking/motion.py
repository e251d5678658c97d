"""A constant-velocity Kalman filter on the ground plane, for all tracks at once.

State per track: position p (x, y) in m and velocity v (m/s). Motion: white-noise acceleration of spectral density
``q`` (m^2/s^3); measurement: the position, with isotropic noise of variance ``r`` (m^2). With isotropic noise and
no coupling between axes, x and y share one 2 x 2 covariance [[pp, pv], [pv, vv]], so the filter keeps three
numbers per track and every step is a few vectorised array operations over the tracks.

Written out rather than taken from filterpy (``filterpy.kalman.KalmanFilter``): filterpy keeps one filter object
per track and steps them one at a time in Python; here one call steps every track (docs/tracking.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["MotionStates"]


@dataclass
class MotionStates:
    """Filter states of N tracks: positions (N, 2) m, velocities (N, 2) m/s, covariances (N, 3) as (pp, pv, vv)."""

    position: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    velocity: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    covariance: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def __len__(self) -> int:
        return len(self.position)

    def predict(self, dt: float, q: float, hold: np.ndarray | None = None) -> None:
        """Advance every track by ``dt`` seconds at constant velocity, growing the covariance by the process noise;
        the tracks ``hold`` (N,) bool marks keep their position (the covariance grows all the same)."""
        if not len(self.position):
            return  # nothing to advance; dt may be any gap then (a Python float's dt**3 overflows past ~1e102 s)
        self.position += self.velocity * (dt if hold is None else np.where(hold, 0.0, dt)[:, None])
        c = self.covariance  # in place, pp first: each line reads the columns after it before they change
        c[:, 0] += 2 * dt * c[:, 1] + dt * dt * c[:, 2] + q * dt**3 / 3
        c[:, 1] += dt * c[:, 2] + q * dt * dt / 2
        c[:, 2] += q * dt

    def innovation_variance(self, r: float) -> np.ndarray:
        """(N,) variance (m^2) of a position measurement about each prediction, per axis."""
        return self.covariance[:, 0] + r

    def correct(self, rows: np.ndarray, measured: np.ndarray, r: float) -> None:
        """Fuse measured positions (K, 2) into the tracks ``rows`` (K,, distinct and ascending)."""
        every = len(rows) == len(self.position)  # rows is then 0..N-1: work on whole arrays, no gathering
        c = self.covariance if every else self.covariance[rows]
        gain = c[:, :2] / (c[:, :1] + r)  # (K, 2): position and velocity gains
        position = self.position if every else self.position[rows]
        residual = measured - position
        c[:, 2] -= gain[:, 1] * c[:, 1]
        c[:, :2] *= 1 - gain[:, :1]
        if every:
            self.position += gain[:, :1] * residual
            self.velocity += gain[:, 1:] * residual
        else:
            self.position[rows] += gain[:, :1] * residual
            self.velocity[rows] += gain[:, 1:] * residual
            self.covariance[rows] = c

    def append(self, positions: np.ndarray, r: float, speed_variance: float) -> None:
        """New tracks at ``positions`` (K, 2), at rest, with position variance r and velocity variance given."""
        start = np.zeros((len(positions), 3))
        start[:, 0], start[:, 2] = r, speed_variance
        self.position = np.concatenate((self.position, positions))
        self.velocity = np.concatenate((self.velocity, np.zeros_like(positions)))
        self.covariance = np.concatenate((self.covariance, start))

    def keep(self, mask: np.ndarray) -> None:
        """Drop the tracks where ``mask`` is False."""
        self.position, self.velocity, self.covariance = self.position[mask], self.velocity[mask], self.covariance[mask]
