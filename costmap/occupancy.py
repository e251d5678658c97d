"""Nav2 costs <-> ``nav_msgs/OccupancyGrid`` values, and the OccupancyGrid record map files and bags carry.

Costmap -> OccupancyGrid (Nav2's costmap publisher table): 0 -> 0, 253 -> 99, 254 -> 100, 255 -> -1 and
1..252 -> 1 + 97 * (c - 1) // 251. OccupancyGrid -> cost (Nav2's static layer ``interpretValue``): -1 -> 255 when
tracking unknown space (else 0), 99 (``inscribed_obstacle_cost_value``) -> 253, >= 100 (``lethal_threshold``)
-> 254, otherwise 0 in trinary mode or floor(v * 254 / 100). The first table squeezes 252 graded costs into 97
values, so a costmap survives OccupancyGrid only up to that quantisation; the .npz export keeps exact costs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from costmap.grid import FREE_SPACE, INSCRIBED, LETHAL, NO_INFORMATION, Costmap2D, GridSpec
from sid.errors import InputError

__all__ = [
    "COST_TO_OCCUPANCY",
    "OCC_FREE",
    "OCC_INSCRIBED",
    "OCC_OCCUPIED",
    "OCC_UNKNOWN",
    "OccupancyGrid",
    "cost_to_occupancy",
    "costmap_to_occupancy",
    "occupancy_to_cost",
]

OCC_UNKNOWN = -1
OCC_FREE = 0
OCC_INSCRIBED = 99
OCC_OCCUPIED = 100
_OVERLAP = 1e-6
"""Cells: two cells that share no more than this much of their width do not overlap (aligned grids touch only at
their borders)."""


def _publisher_table() -> np.ndarray:
    table = np.zeros(256, dtype=np.int8)
    graded = np.arange(1, 253)
    table[1:253] = 1 + (97 * (graded - 1)) // 251
    table[INSCRIBED], table[LETHAL], table[NO_INFORMATION] = OCC_INSCRIBED, OCC_OCCUPIED, OCC_UNKNOWN
    return table


COST_TO_OCCUPANCY = _publisher_table()


@dataclass
class OccupancyGrid:
    """A ``nav_msgs/OccupancyGrid`` payload: int8 data (rows, cols), row 0 = lowest y, values -1 or 0..100.

    origin_yaw: the yaw of the map origin pose (radians); the costmap layers ignore it, as Nav2's static layer does.
    """

    spec: GridSpec
    data: np.ndarray
    origin_yaw: float = 0.0
    frame_id: str = "map"

    def __post_init__(self) -> None:
        self.data = np.asarray(self.data)
        if self.data.dtype != np.int8 or self.data.shape != self.spec.shape:
            raise InputError(
                f"occupancy grid: data must be int8 of shape {self.spec.shape}, got {self.data.dtype} {self.data.shape}"
            )

    def resampled(self, spec: GridSpec) -> OccupancyGrid:
        """This map on another grid ``spec``: each cell of ``spec`` takes the most occupied value of the map cells it
        overlaps (occupied, ``occupancy_to_cost``'s lethal values, over any known value, over unknown), unknown (-1)
        where it overlaps none. Nav2's static layer matches a global costmap to the map instead; sampling the value
        under each cell's centre lost every one-pixel wall of a 0.025 m map on 0.05 m cells, and the planner drove
        through it. A map on the same cells comes back as it is."""
        if spec == self.spec:
            return self
        rank = np.where(_lethal(self.data), OCC_OCCUPIED + 1, self.data.astype(np.int16))  # unknown, -1, lowest
        for axis, (ours, theirs) in enumerate(_overlaps(self.spec, spec)):
            rank = _most_occupied(rank, axis, ours, theirs, spec.shape[axis])
        data = np.where(rank > OCC_OCCUPIED, OCC_OCCUPIED, np.maximum(rank, OCC_UNKNOWN)).astype(np.int8)
        return OccupancyGrid(spec, data, self.origin_yaw, self.frame_id)


def _lethal(data: np.ndarray) -> np.ndarray:
    """Values Nav2's static layer reads as lethal: >= 100 and, read as the unsigned bytes it takes them for, every
    negative value but -1 (unknown)."""
    return (data >= OCC_OCCUPIED) | (data < OCC_UNKNOWN)


def _overlaps(ours: GridSpec, theirs: GridSpec) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """Per axis (rows, then columns), the pairs (our cell, their cell) of overlapping cells of two grids."""
    pairs = []
    for origin, count, other_origin, other_count in (
        (ours.origin_y, ours.height, theirs.origin_y, theirs.height),
        (ours.origin_x, ours.width, theirs.origin_x, theirs.width),
    ):
        their_cells = np.arange(other_count)
        low = other_origin + their_cells * theirs.resolution  # each of their cells spans [low, high)
        high = low + theirs.resolution
        margin = _OVERLAP * min(ours.resolution, theirs.resolution)
        first = np.clip(np.floor((low + margin - origin) / ours.resolution), 0, count).astype(np.intp)
        last = np.clip(np.ceil((high - margin - origin) / ours.resolution), 0, count).astype(np.intp)  # exclusive
        spans = np.maximum(last - first, 0)
        # our cells first .. last - 1 for each of theirs, in one array: a count up that restarts at each span
        step = np.arange(int(spans.sum())) - np.repeat(np.cumsum(spans) - spans, spans)
        pairs.append((np.repeat(first, spans) + step, np.repeat(their_cells, spans)))
    return pairs[0], pairs[1]


def _most_occupied(rank: np.ndarray, axis: int, ours: np.ndarray, theirs: np.ndarray, size: int) -> np.ndarray:
    """``rank`` reduced along ``axis`` onto ``size`` cells: each the largest rank of our cells overlapping it (the
    pairs ``ours``, ``theirs``), -2 where none does."""
    moved = np.moveaxis(rank, axis, 0)
    out = np.full((size, *moved.shape[1:]), -2, dtype=rank.dtype)
    np.maximum.at(out, theirs, moved[ours])
    return np.moveaxis(out, 0, axis)


def cost_to_occupancy(costs: np.ndarray) -> np.ndarray:
    """uint8 Nav2 costs -> int8 OccupancyGrid values (Nav2's costmap publisher table)."""
    costs = np.asarray(costs)
    if costs.dtype != np.uint8:
        raise InputError(f"cost_to_occupancy: costs must be uint8, got {costs.dtype}")
    return COST_TO_OCCUPANCY[costs]


def costmap_to_occupancy(costmap: Costmap2D, frame_id: str = "map") -> OccupancyGrid:
    return OccupancyGrid(costmap.spec, cost_to_occupancy(costmap.costs), frame_id=frame_id)


def occupancy_to_cost(
    data: np.ndarray,
    *,
    track_unknown_space: bool = True,
    trinary: bool = True,
    lethal_threshold: int = OCC_OCCUPIED,
    inscribed_value: int = OCC_INSCRIBED,
) -> np.ndarray:
    """int8 OccupancyGrid values -> uint8 costs, as Nav2's static layer interprets them (its defaults). Nav2 reads
    each value as an unsigned byte: a negative one other than -1 (unknown) is 128-254, lethal (it came out free)."""
    v = np.asarray(data).astype(np.int16)
    v = np.where(v < OCC_UNKNOWN, v + 256, v)
    scaled = np.floor(np.clip(v, 0, None) / lethal_threshold * LETHAL).astype(np.int16)
    cost = np.where(trinary, FREE_SPACE, scaled)
    cost = np.where(v >= lethal_threshold, LETHAL, cost)
    cost = np.where(v == inscribed_value, INSCRIBED, cost)
    cost = np.where(v == OCC_UNKNOWN, NO_INFORMATION if track_unknown_space else FREE_SPACE, cost)
    return cost.astype(np.uint8)
