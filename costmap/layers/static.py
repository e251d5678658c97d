"""The static layer's costs: a map_server map read as Nav2's StaticLayer reads it, sampled onto a grid."""

from __future__ import annotations

import numpy as np

from costmap.grid import NO_INFORMATION, GridSpec
from costmap.occupancy import OccupancyGrid, occupancy_to_cost


def static_costs(grid: OccupancyGrid, spec: GridSpec, track_unknown_space: bool = True) -> np.ndarray:
    """A static map interpreted as Nav2's static layer does, sampled (nearest cell) onto ``spec``.

    Cells of ``spec`` outside the map read NO_INFORMATION (or FREE when unknown space is not tracked).
    """
    costs = occupancy_to_cost(grid.data, track_unknown_space=track_unknown_space)
    if grid.spec == spec:
        return costs
    cells = grid.spec.world_to_cell(np.stack([a.ravel() for a in spec.cell_centres()], axis=1))
    inside = grid.spec.in_bounds(cells)
    out = np.full(spec.height * spec.width, NO_INFORMATION if track_unknown_space else 0, dtype=np.uint8)
    out[inside] = costs[cells[inside, 0], cells[inside, 1]]
    return out.reshape(spec.shape)
