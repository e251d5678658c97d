"""Coherent motion: the classical reference for groups over time, beside ``GroupTracker``.

Two tracked people are linked when, over the last ``window`` seconds, they were within ``distance`` of each other
with velocities differing by at most ``velocity_difference`` in at least ``share`` of the frames in which both were
tracked (and in at least ``min_frames`` frames); groups are the connected components of the links. Standing
people close together are linked as walkers are: it knows motion, not conversations. Parameters chosen by
leave-one-set-out in docs/tracking.md (``sid eval crowd``).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sid.checks import check_number, check_whole
from sid.tracking.groups import connected_components, pair_distance
from sid.tracking.records import TIME_TOLERANCE, TrackedPerson
from sid.tracking.tracker import check_time_order

__all__ = ["CoherentMotion", "CoherentMotionParams"]


@dataclass(frozen=True)
class CoherentMotionParams:
    """distance (m), velocity_difference (m/s): what a coherent pair is in one frame; window (s), share (0-1],
    min_frames: how long it must hold."""

    distance: float = 1.5
    velocity_difference: float = 0.6
    window: float = 2.0
    share: float = 0.6
    min_frames: int = 3

    def __post_init__(self) -> None:
        check_number("coherent motion", "distance", self.distance, low=0, low_open=True, unit="metres")
        check_number("coherent motion", "velocity_difference", self.velocity_difference, low=0, unit="m/s")
        check_number("coherent motion", "window", self.window, low=0, unit="seconds")
        check_number("coherent motion", "share", self.share, low=0, high=1, low_open=True)
        check_whole("coherent motion", "min_frames", self.min_frames, low=1)


@dataclass(frozen=True)
class _Frame:
    timestamp: float
    ids: np.ndarray  # (K,) sorted track ids
    coherent: np.ndarray  # (K, K) bool


class CoherentMotion:
    """Groups of tracks that move together (module docstring). State lives between calls."""

    def __init__(self, params: CoherentMotionParams | None = None) -> None:
        self.params = params or CoherentMotionParams()
        self._frames: deque[_Frame] = deque()

    def reset(self) -> None:
        self._frames.clear()

    def update(self, people: Sequence[TrackedPerson], timestamp: float) -> list[frozenset[int]]:
        """The groups (track ids, two or more) among ``people`` (this frame's tracks) at ``timestamp`` (s);
        TrackingError, changing nothing, when the timestamp is not after the last one."""
        check_time_order("coherent motion: frame", timestamp, self._frames[-1].timestamp if self._frames else None)
        p = self.params
        order = sorted(range(len(people)), key=lambda k: people[k].id)
        ids = np.array([people[k].id for k in order], dtype=np.int64)
        state = np.array([[people[k].x, people[k].y, people[k].vx, people[k].vy] for k in order]).reshape(-1, 4)
        near = pair_distance(state[:, :2]) <= p.distance
        alike = pair_distance(state[:, 2:]) <= p.velocity_difference
        self._frames.append(_Frame(timestamp, ids, near & alike))
        while self._frames and timestamp - self._frames[0].timestamp > p.window + TIME_TOLERANCE:
            self._frames.popleft()
        together = np.zeros((len(ids), len(ids)), dtype=np.int64)
        coherent = np.zeros_like(together)
        for frame in self._frames:
            if not len(frame.ids):
                continue
            rows = np.searchsorted(frame.ids, ids)
            present = (rows < len(frame.ids)) & (frame.ids[np.minimum(rows, len(frame.ids) - 1)] == ids)
            if not present.any():
                continue
            k = np.flatnonzero(present)
            both = np.ix_(k, k)
            together[both] += 1
            coherent[both] += frame.coherent[np.ix_(rows[k], rows[k])]
        linked = (coherent >= p.min_frames) & (coherent >= p.share * together)
        np.fill_diagonal(linked, False)
        groups = [frozenset(ids[rows].tolist()) for rows in connected_components(linked) if len(rows) >= 2]
        return sorted(groups, key=min)
