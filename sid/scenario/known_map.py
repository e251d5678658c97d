"""The known map of a scenario: its declared obstacles rasterised, together with its ``static_map`` file, as the
``nav_msgs/OccupancyGrid`` the costmap's static layer (``costmap.layers.static.StaticLayer``) reads.

A scenario's obstacles are the map the robot knows before it moves, so the planner must know all of each shape,
not only the faces the simulated scan from the start happens to hit. The LiDAR layer still marks what the scan sees
(people are seen only by sensors); the static layer adds every declared obstacle whole.

Rasterisation (world frame, metres): a cell is occupied when the shape reaches into it, with cells as
``costmap.grid.GridSpec.world_to_cell`` assigns points (a point on a cell border belongs to the cell above / to the
right, as a LiDAR hit there would): a box fills every cell from the one holding ``min`` to the one holding ``max``;
a circle every cell whose square overlaps the disc; a wall every cell its polyline passes through, a wall along the
map's upper or right border the last row or column (the cells above / to the right of it lie outside the map), also
when the map's size is not a whole number of cells and its border lies up to half a cell beyond the grid's.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from costmap.grid import GridSpec
from costmap.occupancy import OCC_OCCUPIED, OCC_UNKNOWN, OccupancyGrid
from sid.scenario.obstacles import BoxObstacle, CircleObstacle, Obstacle, SegmentObstacle

__all__ = ["known_map", "obstacle_mask"]


def _mark_points(mask: np.ndarray, spec: GridSpec, xy: np.ndarray) -> None:
    """Mark the cells holding the points ``xy`` (N, 2); a point on or up to half a cell beyond the grid's upper or
    right border is in the last row or column, so that a wall drawn along the map's edge is in the map: the grid has
    ``round(size / resolution)`` cells, so its border lies within half a cell of the declared one."""
    x0, y0, x1, y1 = spec.bounds
    slack = spec.resolution / 2
    inside = (xy[:, 0] >= x0) & (xy[:, 0] <= x1 + slack) & (xy[:, 1] >= y0) & (xy[:, 1] <= y1 + slack)
    cells = spec.world_to_cell(xy[inside])
    rows = np.minimum(cells[:, 0], spec.height - 1)
    cols = np.minimum(cells[:, 1], spec.width - 1)
    mask[rows, cols] = True


def obstacle_mask(obstacles: Sequence[Obstacle], spec: GridSpec) -> np.ndarray:
    """Boolean (rows, cols): the cells of ``spec`` the obstacles occupy (see the module docstring)."""
    mask = np.zeros(spec.shape, dtype=bool)
    res = spec.resolution
    for ob in obstacles:
        if isinstance(ob, BoxObstacle):
            window = spec.window(ob.min, ob.max)
            if window is not None:
                mask[window.slices] = True
        elif isinstance(ob, CircleObstacle):
            (cx, cy), r = ob.center, ob.radius
            window = spec.window((cx - r, cy - r), (cx + r, cy + r))
            if window is None:
                continue
            xs, ys = spec.cell_axes(window)
            dx = np.maximum(np.abs(xs - cx) - res / 2, 0.0)  # distance from the centre to the cell's square
            dy = np.maximum(np.abs(ys - cy) - res / 2, 0.0)
            mask[window.slices] |= dx**2 + dy**2 <= r**2
        elif isinstance(ob, SegmentObstacle):
            points = np.asarray(ob.points, dtype=float)
            for a, b in zip(points[:-1], points[1:], strict=True):
                # Samples every eighth of a cell: a cell the line crosses by less than that at a corner may be
                # missed, which no disc robot can use.
                n = max(1, int(np.ceil(np.hypot(*(b - a)) / (res / 8))))
                t = np.linspace(0.0, 1.0, n + 1)[:, None]
                _mark_points(mask, spec, a + t * (b - a))
    return mask


def known_map(obstacles: Sequence[Obstacle], spec: GridSpec, static_map: OccupancyGrid | None = None) -> OccupancyGrid:
    """The static layer's map on the scenario's grid ``spec``: ``static_map`` (if any) sampled onto it (nearest
    cell; unknown, -1, outside it), with every cell an obstacle occupies set to occupied (100).

    Without a map file every other cell is unknown (-1): the static layer reads it as free unless unknown space is
    tracked (``layers.obstacle.track_unknown_space``), so the LiDAR layer decides there, as without obstacles.
    """
    if static_map is None:
        data = np.full(spec.shape, OCC_UNKNOWN, dtype=np.int8)
    else:
        data = static_map.resampled(spec).data.copy()
    data[obstacle_mask(obstacles, spec)] = OCC_OCCUPIED
    frame = "map" if static_map is None else static_map.frame_id
    return OccupancyGrid(spec, data, frame_id=frame)
