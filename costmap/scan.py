"""2D laser scans: the ``sensor_msgs/LaserScan``-like record the obstacle layer reads.

Frames: the sensor pose (x, y, yaw) is in the world frame (REP-103, metres, radians); beam angles are relative
to the sensor's yaw, counter-clockwise, as in ``sensor_msgs/LaserScan``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sid.checks import check_number, check_numbers
from sid.errors import InputError

__all__ = ["LaserScan"]


@dataclass(frozen=True)
class LaserScan:
    """One scan. ranges (N,) metres: ``inf`` = no return within ``range_max``, ``nan`` = invalid beam.

    Readings below ``range_min`` are invalid and readings above ``range_max`` are "no return", as
    ``sensor_msgs/LaserScan`` prescribes. Beam i points at yaw + angle_min + i * angle_increment (world frame).
    """

    ranges: np.ndarray
    angle_min: float
    angle_increment: float
    range_max: float
    pose: tuple[float, float, float]
    range_min: float = 0.0

    def __post_init__(self) -> None:
        ranges = np.asarray(self.ranges, dtype=float)
        if ranges.ndim != 1 or ranges.size == 0:
            raise InputError(f"scan.ranges must be a non-empty 1-D array, got shape {ranges.shape}")
        object.__setattr__(self, "ranges", ranges)
        pose = tuple(float(v) for v in self.pose)
        if len(pose) != 3 or not np.isfinite(pose).all():
            raise InputError(f"scan.pose must be a finite (x, y, yaw), got {self.pose}")
        object.__setattr__(self, "pose", pose)
        check_numbers("scan", self, ("angle_min", "angle_increment"), unit="radians")
        if self.angle_increment == 0:
            raise InputError("scan: angle_increment must not be 0")
        check_number("scan", "range_min", self.range_min, low=0, unit="metres")
        check_number("scan", "range_max", self.range_max, low=self.range_min, low_open=True, unit="metres")

    @property
    def angles(self) -> np.ndarray:
        """World-frame yaw of every beam (N,). The pose's yaw is taken to [-pi, pi] first: added to a yaw of 1e308,
        the beams' offsets would vanish and every beam point the same way."""
        yaw = math.remainder(self.pose[2], math.tau)
        return yaw + self.angle_min + self.angle_increment * np.arange(len(self.ranges))

    @property
    def directions(self) -> np.ndarray:
        """Unit world-frame direction of every beam (N, 2)."""
        a = self.angles
        return np.stack([np.cos(a), np.sin(a)], axis=1)

    def valid_ranges(self) -> np.ndarray:
        """Ranges with the LaserScan conventions applied: nan = invalid (incl. < range_min), inf = no return."""
        r = self.ranges.copy()
        with np.errstate(invalid="ignore"):
            r[r < self.range_min] = np.nan
            r[r > self.range_max] = np.inf
        return r

    def hit_points(self) -> np.ndarray:
        """World (x, y) of every return (M, 2); beams without a valid return are left out."""
        r = self.valid_ranges()
        hit = np.isfinite(r)
        return np.asarray(self.pose[:2]) + self.directions[hit] * r[hit, None]
