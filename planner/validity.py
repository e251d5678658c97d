"""State validity for OMPL, and the exact check every returned path goes through.

OMPL checks a motion by calling the state validity checker at points at most one cell apart (the state space's
longest valid segment is set to the costmap resolution); the checker reads the precomputed ``plannable`` mask of
``planner.problem.CostField``, so one call is a dictionary-free list lookup returning a Python ``bool`` (numpy
bools would be converted on every call).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from planner.problem import CostField

__all__ = ["PathCheck", "check_path", "interpolate", "state_validity_checker"]


def state_validity_checker(field: CostField) -> Callable[[Any], bool]:
    """A callable for ``SpaceInformation.setStateValidityChecker``: state -> plannable (Python bool)."""
    is_plannable = field.is_plannable

    def is_valid(state: Any) -> bool:  # an OMPL RealVectorStateSpace state
        return is_plannable(state[0], state[1])

    return is_valid


def interpolate(path: np.ndarray, spacing: float) -> np.ndarray:
    """Points along a polyline (N, 2) at most ``spacing`` apart, every vertex included (world frame, metres)."""
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    if len(path) < 2:
        return path.copy()
    d = np.diff(path, axis=0)
    n = np.maximum(1, np.ceil(np.hypot(d[:, 0], d[:, 1]) / spacing)).astype(np.int64)
    seg = np.repeat(np.arange(len(d)), n)
    t = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / n[seg]
    return np.vstack([path[seg] + t[:, None] * d[seg], path[-1:]])


@dataclass(frozen=True)
class PathCheck:
    """Result of checking every interpolated sample of a path against the exact free mask."""

    valid: bool
    samples: int
    bad_points: np.ndarray  # (K, 2) world points of samples that are not free

    def describe(self) -> str:
        """The result in words: every sample free, no sample (an empty path: invalid), or the first in collision."""
        if self.valid:
            return f"all {self.samples} samples free"
        if not self.samples:
            return "no samples: the path is empty"
        x, y = self.bad_points[0]
        return f"{len(self.bad_points)} of {self.samples} samples in collision, first at ({x:.3f}, {y:.3f}) m"


def check_path(field: CostField, path: np.ndarray, spacing: float | None = None) -> PathCheck:
    """Check a path (N, 2) at samples ``spacing`` apart (default a quarter cell) against the exact free mask."""
    samples = interpolate(path, spacing or field.resolution / 4)
    ok = field.free_at(samples)
    return PathCheck(bool(ok.all()) and len(samples) > 0, len(samples), samples[~ok])
