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
        """This map on another grid ``spec`` (nearest cell: each cell of ``spec`` takes the value under its centre;
        unknown, -1, outside this map)."""
        if spec == self.spec:
            return self
        cells = self.spec.world_to_cell(np.stack([a.ravel() for a in spec.cell_centres()], axis=1))
        inside = self.spec.in_bounds(cells)
        data = np.full(spec.height * spec.width, OCC_UNKNOWN, dtype=np.int8)
        data[inside] = self.data[cells[inside, 0], cells[inside, 1]]
        return OccupancyGrid(spec, data.reshape(spec.shape), self.origin_yaw, self.frame_id)


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
    """int8 OccupancyGrid values -> uint8 costs, as Nav2's static layer interprets them (its defaults)."""
    v = np.asarray(data).astype(np.int16)
    scaled = np.floor(np.clip(v, 0, None) / lethal_threshold * LETHAL).astype(np.int16)
    cost = np.where(trinary, FREE_SPACE, scaled)
    cost = np.where(v >= lethal_threshold, LETHAL, cost)
    cost = np.where(v == inscribed_value, INSCRIBED, cost)
    cost = np.where(v == OCC_UNKNOWN, NO_INFORMATION if track_unknown_space else FREE_SPACE, cost)
    return cost.astype(np.uint8)
