"""A real-crowd-like scene for ``sid bench``'s ``crowd/N``: real pedestrian trajectories (ETH/BIWI, UCY; read by
``sid.experiments.trajectories``) replayed as a robot's detections and stacked until N people are present in every
frame.

How the scene is built (``CrowdReplay.scene``):

1. each set is replayed once at ``rate`` (15 Hz, a camera's) by ``replay`` with its defaults: seeded 0.1 m noise,
   10 % missed detections, facing unknown (the sets have none);
2. each replay is cut into consecutive, disjoint stretches as long as the scene; a copy is one stretch placed in a
   tile of its own (tiles as large as the largest set plus ``TILE_MARGIN``, in rows), so copies never overlap and
   each keeps its set's real density and walking groups;
3. copies are added one at a time, each the stretch that fills most of what is still missing below N people (summed
   over the frames), until at least N people are present in every frame;
4. people who walk alone (in no annotated group) are then left out, a whole trajectory at a time, last copy first,
   as long as N people stay present in every frame.

Positions are in the scene's ground frame (metres; the sets' own frames moved into their tiles), timestamps in
seconds from 0. A person is present in a frame when the set has them there (detected or missed).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sid.errors import InputError
from sid.experiments.trajectories import ReplayFrame, ReplaySettings, TrajectorySet, replay
from sid.perception.people import Person

__all__ = ["CrowdCopy", "CrowdReplay", "CrowdScene", "TILE_MARGIN"]

TILE_MARGIN = 2.0
"""Metres between the areas of two copies: walkers of different copies never come closer than this."""


@dataclass(frozen=True)
class CrowdCopy:
    """One stretch of a set in the scene: the set's ``name``, the time (s) in the set of the stretch's first frame,
    and the ``offset`` (m) added to the set's positions."""

    name: str
    start: float
    offset: tuple[float, float]


@dataclass(frozen=True, eq=False)
class CrowdScene:
    """The stacked scene: one ``ReplayFrame`` per time step (detections and truth in the scene's ground frame, m;
    a person's id is ``copy index * id_stride`` + their id in the set), the copies, the rate (Hz)."""

    frames: tuple[ReplayFrame, ...]
    copies: tuple[CrowdCopy, ...]
    rate: float
    id_stride: int

    def present(self) -> np.ndarray:
        """(F,) int: the people present in each frame."""
        return np.array([len(f.truth_ids) for f in self.frames], dtype=np.int64)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The lower and upper (x, y) corners (m) of every true position of the scene."""
        positions = np.concatenate([f.truth_positions for f in self.frames])
        return positions.min(axis=0), positions.max(axis=0)


class CrowdReplay:
    """``sets`` replayed once at ``rate`` (Hz) with ``seed``; ``scene`` stacks stretches of them (module docstring)."""

    def __init__(self, sets: Sequence[TrajectorySet], rate: float = 15.0, seed: int = 0) -> None:
        if not sets:
            raise InputError("bench: a crowd scene needs at least one trajectory set")
        self.sets = tuple(sets)
        self.rate = float(rate)
        self.replays = [list(replay(s, ReplaySettings(rate=rate, seed=seed))) for s in self.sets]
        self.id_stride = 1 + max(int(np.concatenate(s.ids).max()) for s in self.sets)
        extents = [np.ptp(np.concatenate(s.positions), axis=0) for s in self.sets]
        self.tile = np.max(extents, axis=0) + TILE_MARGIN  # (width, height) m of every tile

    def scene(self, n: int, frames: int) -> CrowdScene:
        """``frames`` time steps with ``n`` or more people present in each; ValueError when the sets hold too few."""
        if n < 1 or frames < 1:
            raise InputError(f"bench: a crowd scene needs n >= 1 people and frames >= 1, got {n} and {frames}")
        stretches = [(k, start) for k, r in enumerate(self.replays) for start in range(0, len(r) - frames + 1, frames)]
        counts = np.array([[len(f.truth_ids) for f in self._stretch(k, s, frames)] for k, s in stretches])
        counts = counts.reshape(len(stretches), frames)
        chosen: list[int] = []
        total = np.zeros(frames, dtype=np.int64)
        while total.min() < n:
            gain = np.minimum(n, total + counts).sum(axis=1)
            gain[chosen] = -1
            if not stretches or gain.max() <= np.minimum(n, total).sum():
                raise InputError(f"bench: the trajectory sets hold fewer than {n} people in some of {frames} frames")
            chosen.append(int(np.argmax(gain)))
            total += counts[chosen[-1]]
        left_out = self._left_out([stretches[c] for c in chosen], frames, total, n)
        columns = math.ceil(math.sqrt(len(chosen)))
        copies, parts = [], []
        for index, c in enumerate(chosen):
            k, start = stretches[c]
            corner = np.concatenate(self.sets[k].positions).min(axis=0)
            offset = np.array([index % columns, index // columns]) * self.tile - corner
            copies.append(CrowdCopy(self.sets[k].name, float(self.replays[k][start].timestamp), tuple(offset.tolist())))
            parts.append(self._moved(self._stretch(k, start, frames), offset, index, left_out[index]))
        merged = tuple(_merge([part[t] for part in parts], t / self.rate) for t in range(frames))
        return CrowdScene(merged, tuple(copies), self.rate, self.id_stride)

    def _stretch(self, k: int, start: int, frames: int) -> list[ReplayFrame]:
        return self.replays[k][start : start + frames]

    def _left_out(self, stretches: list[tuple[int, int]], frames: int, total: np.ndarray, n: int) -> list[set[int]]:
        """Per copy, the ids (in its set) of people walking alone left out while ``n`` stay in every frame."""
        left_out: list[set[int]] = [set() for _ in stretches]
        for index in reversed(range(len(stretches))):
            k, start = stretches[index]
            grouped = set().union(*self.sets[k].groups)
            stretch = self._stretch(k, start, frames)
            for person in sorted(set(np.concatenate([f.truth_ids for f in stretch]).tolist()) - grouped):
                here = np.array([person in f.truth_ids for f in stretch])
                if (total - here).min() >= n:
                    total = total - here
                    left_out[index].add(person)
        return left_out

    def _moved(
        self, stretch: list[ReplayFrame], offset: np.ndarray, index: int, left_out: set[int]
    ) -> list[ReplayFrame]:
        """The frames of one copy: ``left_out`` removed, positions moved by ``offset`` (m), ids made unique."""
        base, (dx, dy) = index * self.id_stride, offset.tolist()
        out = []
        for frame in stretch:
            keep = np.array([i not in left_out for i in frame.truth_ids.tolist()], dtype=bool)
            detections = [Person(base + p.id, p.x + dx, p.y + dy) for p in frame.detections if p.id not in left_out]
            out.append(ReplayFrame(0.0, detections, frame.truth_ids[keep] + base, frame.truth_positions[keep] + offset))
        return out


def _merge(parts: Sequence[ReplayFrame], timestamp: float) -> ReplayFrame:
    return ReplayFrame(
        timestamp,
        [p for part in parts for p in part.detections],
        np.concatenate([part.truth_ids for part in parts]),
        np.concatenate([part.truth_positions for part in parts]).reshape(-1, 2),
    )
