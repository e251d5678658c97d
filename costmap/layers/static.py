"""Nav2's static layer: a map_server map, read as Nav2 reads it and sampled onto the costmap's grid."""

from __future__ import annotations

import numpy as np

from costmap.combine import CombinationMethod
from costmap.grid import GridSpec, Window
from costmap.layer import Layer, LayerInputs
from costmap.occupancy import OccupancyGrid, occupancy_to_cost

__all__ = ["StaticLayer", "static_costs"]


def static_costs(grid: OccupancyGrid, spec: GridSpec, track_unknown_space: bool = True) -> np.ndarray:
    """A static map interpreted as Nav2's static layer does, on ``spec`` (``OccupancyGrid.resampled``: each cell
    the most occupied map cell it overlaps).

    Cells of ``spec`` outside the map read NO_INFORMATION (or FREE when unknown space is not tracked).
    """
    return occupancy_to_cost(grid.resampled(spec).data, track_unknown_space=track_unknown_space)


class StaticLayer(Layer):
    """The map, written first by true overwrite; it changes nothing after the first update."""

    name = "static"
    combination: CombinationMethod = "true_overwrite"

    def __init__(self, spec: GridSpec, grid: OccupancyGrid, track_unknown_space: bool = True) -> None:
        super().__init__(spec)
        self.costs = static_costs(grid, spec, track_unknown_space)
        self._new_map = True

    def update(self, inputs: LayerInputs, changed: Window | None) -> Window | None:
        """The whole grid once, for the new map; nothing afterwards."""
        window = self.spec.whole if self._new_map else None
        self._new_map = False
        return window
