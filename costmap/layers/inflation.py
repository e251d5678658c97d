"""Nav2's inflation layer: costs that fall off with the distance to the nearest lethal cell.

Formula (nav2_costmap_2d ``InflationLayer::computeCost``), with d the distance between cell centres in metres:
d = 0 -> LETHAL (254); d <= inscribed_radius -> INSCRIBED (253);
otherwise floor(252 * exp(-cost_scaling_factor * (d - inscribed_radius))).
Only cells within ``ceil(inflation_radius / resolution)`` cells of a lethal cell get a cost (Nav2's
``cellDistance`` rounds up, so the reach can exceed ``inflation_radius`` by up to one cell).

Distances come from an exact Euclidean distance transform (OpenCV's Felzenszwalb-Huttenlocher
``DIST_MASK_PRECISE``, as newer Nav2 does, and faster than ``scipy.ndimage.distance_transform_edt``; timings in
docs/parameters.md). It gives d in cells as the float32 nearest the exact distance (the tests hold it to scipy's);
squaring and rounding recovers the exact integer squared distance (``squared_distance_to_lethal_cells``), which
indexes a cost table built with Nav2's formula, so every cell gets exactly Nav2's value. The planner's clearance
test (``planner.problem``) reads the same squared distances.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from costmap.grid import FREE_SPACE, INSCRIBED, LETHAL, MAX_NON_OBSTACLE, GridSpec, Window, nonzero_cells
from costmap.layer import Layer, LayerInputs
from sid.checks import check_number
from sid.errors import InputError

__all__ = [
    "InflationLayer",
    "InflationParams",
    "SQUARED_DISTANCE_EXACT",
    "check_reach",
    "inflation_cost",
    "squared_distance_to_lethal_cells",
]


@dataclass(frozen=True)
class InflationParams:
    """Nav2 inflation parameters and defaults (metres, 1/metre).

    inflate_unknown: also write graded costs into unknown (255) cells; by default only costs >= 253 replace
    unknown, as in Nav2.
    """

    inflation_radius: float = 0.55
    cost_scaling_factor: float = 10.0
    inflate_unknown: bool = False

    def __post_init__(self) -> None:
        check_number("inflation", "inflation_radius", self.inflation_radius, low=0, unit="metres")
        check_number("inflation", "cost_scaling_factor", self.cost_scaling_factor, low=0)


def check_reach(spec: GridSpec, inflation_radius: float, field: str) -> None:
    """ValueError, naming ``field``, for an inflation radius (m) beyond the map's diagonal: costs cannot spread farther
    than the map, and the cost table grows with the square of the radius in cells."""
    diagonal = math.hypot(*spec.size_m)
    if inflation_radius > diagonal:
        raise InputError(
            f"{field}: {inflation_radius:g} m is more than the map's diagonal ({diagonal:g} m), the farthest any cost "
            "can spread; use at most that"
        )


def inflation_cost(distance_m: np.ndarray, inscribed_radius: float, cost_scaling_factor: float) -> np.ndarray:
    """Nav2's inflation cost (uint8) for distances (metres) to the nearest lethal cell; no radius cut-off here."""
    d = np.asarray(distance_m, dtype=float)
    beyond = np.maximum(d - inscribed_radius, 0.0)  # cells within the radius are INSCRIBED below: no exp(+large)
    decay = np.floor(MAX_NON_OBSTACLE * np.exp(-cost_scaling_factor * beyond))
    cost = np.where(d <= inscribed_radius, INSCRIBED, np.clip(decay, 0, MAX_NON_OBSTACLE))
    return np.where(d == 0, LETHAL, cost).astype(np.uint8)


SQUARED_DISTANCE_EXACT = 2**22
"""``squared_distance_to_lethal_cells`` is the exact integer below this (cells^2, distances under 2048 cells): a
float32 distance squared and rounded resolves whole numbers that far; beyond, within float32's precision."""


def squared_distance_to_lethal_cells(lethal: np.ndarray, cap: float) -> np.ndarray:
    """Squared Euclidean distance (cells^2, whole numbers in float32) from every cell centre of a (rows, cols) grid to
    the nearest ``lethal`` cell centre, at most ``cap`` (farther cells read ``cap`` rounded): exact below
    ``SQUARED_DISTANCE_EXACT``. Undefined (large) when ``lethal`` has no True cell; callers check that first."""
    distance = cv2.distanceTransform((~lethal).view(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
    np.minimum(distance, np.float32(np.sqrt(cap)), out=distance)  # clip first: the squares stay small
    return np.rint(np.square(distance, out=distance), out=distance)


class InflationLayer(Layer):
    """Inflates the lethal cells of the combined grid (it reads the master, as Nav2's does); keeps its own grid of
    inflation costs. Put it last.

    ``inscribed_radius`` is the robot's radius (metres): Nav2's inscribed radius of a circular footprint. Combined by
    max with Nav2's rule for unknown cells (``max_keep_unknown``), or ``max_nonzero`` with ``inflate_unknown``.
    """

    name = "inflation"

    def __init__(self, spec: GridSpec, params: InflationParams, inscribed_radius: float) -> None:
        check_number("inflation layer", "robot.radius (inscribed radius)", inscribed_radius, low=0, unit="metres")
        check_reach(spec, params.inflation_radius, "inflation layer: inflation_radius")
        self.combination = "max_nonzero" if params.inflate_unknown else "max_keep_unknown"
        super().__init__(spec)
        self.params = params
        self.inscribed_radius = float(inscribed_radius)
        self.cell_radius = spec.cell_distance(params.inflation_radius)
        # Cost by exact squared cell distance 0..R^2; one extra entry (0) for everything farther.
        d2 = np.arange(self.cell_radius**2 + 2)
        self._cost_by_d2 = inflation_cost(np.sqrt(d2) * spec.resolution, inscribed_radius, params.cost_scaling_factor)
        self._cost_by_d2[-1] = FREE_SPACE
        # The same as OpenCV's 256-entry lookup table, when the reach allows one (beyond it: never indexed).
        self._lut = np.pad(self._cost_by_d2, (0, 256 - len(self._cost_by_d2))) if len(self._cost_by_d2) <= 256 else None
        # The lethal cells ``costs`` was computed from (none yet: all FREE is right for them).
        self._lethal = np.zeros(spec.shape, dtype=bool)

    def update(self, inputs: LayerInputs, changed: Window | None) -> Window | None:
        """Costs change within reach of whatever the layers before this one changed."""
        return None if changed is None else changed.grown(self.cell_radius, self.spec)

    def update_windows(self, inputs: LayerInputs, changed: Sequence[Window]) -> list[Window]:
        """Costs change within reach of each window the layers before this one changed."""
        return [window.grown(self.cell_radius, self.spec) for window in changed]

    def write(self, master: np.ndarray, window: Window) -> None:
        """Bring the inflation costs up to date with the lethal cells of ``master`` and combine them over ``window``.

        A cell's cost depends only on the lethal cells within ``cell_radius`` of it, so only the cells within reach of
        a lethal cell that appeared or disappeared since the last write are recomputed (from the lethal cells within
        reach of them, wherever those lie: a change near the edge of this window may be within reach of another
        window written later, which will see it as known): the cost of an update grows with the area that changed,
        not with the map, and every cell gets the value a recomputation of the whole map would give (tests compare
        the two). Lethal cells change only inside update windows, and each write compares the window grown by the
        reach, so none is missed.
        """
        source = window.grown(self.cell_radius, self.spec)
        lethal = master[source.slices] == LETHAL
        known = self._lethal[source.slices]
        changed = lethal != known
        if changed.any():
            for affected in self._affected(changed, source):
                reach = affected.grown(self.cell_radius, self.spec)
                inner = slice(affected.row0 - reach.row0, affected.row1 - reach.row0)
                inner_cols = slice(affected.col0 - reach.col0, affected.col1 - reach.col0)
                inflated = self._inflate(master[reach.slices] == LETHAL)
                self.costs[affected.slices] = inflated[inner, inner_cols]
            known[...] = lethal
        super().write(master, window)

    def _affected(self, changed: np.ndarray, source: Window) -> list[Window]:
        """Windows holding every cell within reach of the ``changed`` cells (bool over ``source``), clipped to the
        grid: the grid is cut into tiles of ``cell_radius`` cells, the tiles holding a change and their
        neighbours are grouped into 8-connected clusters (OpenCV on the small tile grid: faster than
        scipy.ndimage's dilation and labelling there) and each cluster's bounding box is one window. A tile's
        neighbours reach at least ``cell_radius`` cells beyond it."""
        t = max(self.cell_radius, 1)
        rows, cols = nonzero_cells(changed)
        tiles = np.zeros((changed.shape[0] // t + 3, changed.shape[1] // t + 3), dtype=np.uint8)
        tiles[rows // t + 1, cols // t + 1] = 1  # one empty tile of margin on every side
        grown = cv2.dilate(tiles, np.ones((3, 3), dtype=np.uint8))
        _, _, boxes, _ = cv2.connectedComponentsWithStats(grown, connectivity=8)
        windows = []
        for tile_col, tile_row, tile_cols, tile_rows, _ in boxes[1:].tolist():  # label 0: the tiles of no cluster
            # Tile i (margin included) covers rows (i - 1) * t .. i * t - 1 of ``source``.
            row0, row1 = source.row0 + (tile_row - 1) * t, source.row0 + (tile_row + tile_rows - 1) * t
            col0, col1 = source.col0 + (tile_col - 1) * t, source.col0 + (tile_col + tile_cols - 1) * t
            windows.append(Window(row0, row1, col0, col1).grown(0, self.spec))  # clipped
        return windows

    def _inflate(self, lethal: np.ndarray) -> np.ndarray:
        """Nav2's cost for every cell of ``lethal`` (bool) within reach of a True cell, 0 beyond."""
        if self.cell_radius == 0 or not lethal.any():
            return np.where(lethal, LETHAL, FREE_SPACE).astype(np.uint8)
        d2 = squared_distance_to_lethal_cells(lethal, len(self._cost_by_d2) - 1)  # cap: the "beyond reach" entry
        if self._lut is not None:  # the usual case (reach <= 15 cells): OpenCV's lookup is faster (docs/parameters.md)
            return cv2.LUT(d2.astype(np.uint8), self._lut)
        return self._cost_by_d2[d2.astype(np.int32)]
