"""The grid every layer writes into: geometry, Nav2 cost values and world <-> cell conversions.

Frames: world frame (REP-103, metres). Cell (row, col) covers x in [origin_x + col*res, origin_x + (col+1)*res)
and y in [origin_y + row*res, ...): row 0 is the lowest y (as in nav_msgs/OccupancyGrid; images flip it).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from sid.checks import check_limit, check_number, check_numbers, check_whole
from sid.errors import InputError

__all__ = [
    "BORDER_TOLERANCE",
    "Costmap2D",
    "FREE_SPACE",
    "GridSpec",
    "INSCRIBED",
    "LETHAL",
    "MAX_NON_OBSTACLE",
    "MAX_ORIGIN",
    "NO_INFORMATION",
    "SEPARATE_WINDOW_CELLS",
    "Window",
    "disjoint",
    "nonzero_cells",
    "union",
]

FREE_SPACE = 0
MAX_NON_OBSTACLE = 252
INSCRIBED = 253
LETHAL = 254
NO_INFORMATION = 255


@dataclass(frozen=True)
class Window:
    """A rectangle of cells: rows [row0, row1) and columns [col0, col1) of a grid (half-open, like slices)."""

    row0: int
    row1: int
    col0: int
    col1: int

    @property
    def slices(self) -> tuple[slice, slice]:
        """(rows, cols) slices that index the window in a (rows, cols) array."""
        return slice(self.row0, self.row1), slice(self.col0, self.col1)

    def union(self, other: Window | None) -> Window:
        """The smallest window holding both."""
        if other is None:
            return self
        return Window(
            min(self.row0, other.row0),
            max(self.row1, other.row1),
            min(self.col0, other.col0),
            max(self.col1, other.col1),
        )

    def grown(self, cells: int, spec: GridSpec) -> Window:
        """This window with ``cells`` more on every side, clipped to the grid of ``spec``."""
        return Window(
            max(self.row0 - cells, 0),
            min(self.row1 + cells, spec.height),
            max(self.col0 - cells, 0),
            min(self.col1 + cells, spec.width),
        )

    def clipped(self, spec: GridSpec) -> Window | None:
        """The part inside the grid of ``spec``; None when nothing is."""
        r0, r1 = max(self.row0, 0), min(self.row1, spec.height)
        c0, c1 = max(self.col0, 0), min(self.col1, spec.width)
        return Window(r0, r1, c0, c1) if r0 < r1 and c0 < c1 else None


def union(*windows: Window | None) -> Window | None:
    """The smallest window holding every given window; None when none is given."""
    given = [window for window in windows if window is not None]
    if not given:
        return None
    return Window(
        min(w.row0 for w in given), max(w.row1 for w in given), min(w.col0 for w in given), max(w.col1 for w in given)
    )


SEPARATE_WINDOW_CELLS = 50_000
"""``disjoint`` keeps two windows apart only when that spares more than this many cells: every window costs each layer
of a costmap a write and inflation a search for changes, about what this many more cells cost in one window
(docs/benchmarks.md, "Costmap")."""


def disjoint(windows: Iterable[Window | None], slack: int = SEPARATE_WINDOW_CELLS) -> list[Window]:
    """Windows that cover every cell of ``windows`` and share no cell: given windows that overlap, or whose union box
    holds at most ``slack`` cells more than the two, are merged into that box until no two are left so. Changes far
    apart stay apart, where ``union``'s one box (Nav2's update bounds) would span the cells between them.

    On (row0, row1, col0, col1) tuples of Python ints: a frame has tens of windows, and a ``Window`` per step of the
    merging would cost more than the merging."""
    out: list[tuple[int, int, int, int]] = []
    for window in windows:
        if window is None:
            continue
        r0, r1, c0, c1 = window.row0, window.row1, window.col0, window.col1
        i = 0
        while i < len(out):  # conditional expressions, not min/max calls: this loop runs per window per frame
            b0, b1, d0, d1 = out[i]
            u0, u1 = (r0 if r0 < b0 else b0), (r1 if r1 > b1 else b1)
            v0, v1 = (c0 if c0 < d0 else d0), (c1 if c1 > d1 else d1)
            overlap = r0 < b1 and b0 < r1 and c0 < d1 and d0 < c1
            if overlap or (u1 - u0) * (v1 - v0) - (r1 - r0) * (c1 - c0) - (b1 - b0) * (d1 - d0) <= slack:
                del out[i]
                grew = (u0, u1, v0, v1) != (b0, b1, d0, d1)
                r0, r1, c0, c1 = u0, u1, v0, v1
                if not grew:
                    break
                i = 0  # the merged box grew: it may now reach windows already passed
            else:
                i += 1
        out.append((r0, r1, c0, c1))
    return [Window(*box) for box in out]


def nonzero_cells(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rows, cols) of the True cells of a 2-D boolean ``mask``, as ``np.nonzero`` gives them, but through the flat
    indices: numpy's 2-D ``nonzero`` is much slower on a sparse mask."""
    rows, cols = np.divmod(np.flatnonzero(mask), mask.shape[1])
    return rows, cols


BORDER_TOLERANCE = 1e-6
"""Cells: a point this near below a cell border counts as on it, so in the cell above / to the right. (y - origin) /
resolution rounds a border point to 91.99999999999999 for 4.6 m on 0.05 m cells (and differently for another
origin), which put a box at y = 4.6 m into the row below it. Above the rounding of any coordinate within
``MAX_ORIGIN`` (4e-8 cells at 0.05 m) and far below a cell."""

MAX_ORIGIN = 1e7
"""The farthest (m, along x or y) a map's origin may lie from the world's: 10 000 km holds any UTM coordinate, and
float64 still resolves nanometres there; far beyond, a person's offset into the map is lost to rounding
(docs/parameters.md, "Input limits")."""


@dataclass(frozen=True)
class GridSpec:
    """Grid geometry: resolution (m/cell), origin (world x, y of the lower-left corner), size in cells."""

    resolution: float
    origin_x: float
    origin_y: float
    width: int
    height: int

    def __post_init__(self) -> None:
        check_number("map", "resolution", self.resolution, low=0, low_open=True, unit="metres")
        check_numbers("map", self, ("origin_x", "origin_y"), low=-MAX_ORIGIN, high=MAX_ORIGIN, unit="metres")
        for name in ("width", "height"):  # whole cells, stored as Python ints (a bool or 10.5 is no size)
            object.__setattr__(self, name, check_whole("map", name, getattr(self, name), low=1))
        _check_cells(self.width, self.height)

    @classmethod
    def from_size(cls, resolution: float, origin: tuple[float, float], size_m: tuple[float, float]) -> GridSpec:
        """A grid covering ``size_m`` (width, height in metres) from ``origin``; LimitError (a ValueError) above
        ``Limits.map_cells`` cells, before any number of cells is formed."""
        check_number("map", "resolution", resolution, low=0, low_open=True, unit="metres")
        for name, metres in zip(("width", "height"), size_m, strict=True):
            check_number("map", name, metres, low=0, unit="metres")
        _check_cells(*(round(s / resolution, 0) for s in size_m))
        width, height = (int(round(s / resolution)) for s in size_m)
        return cls(float(resolution), float(origin[0]), float(origin[1]), width, height)

    @property
    def shape(self) -> tuple[int, int]:
        """(rows, cols) of the cost arrays."""
        return (self.height, self.width)

    @property
    def size_m(self) -> tuple[float, float]:
        return (self.width * self.resolution, self.height * self.resolution)

    def world_to_cell(self, xy: np.ndarray) -> np.ndarray:
        """World points (N, 2) -> integer cells (N, 2) as (row, col); may lie outside the grid. A point on a cell
        border is in the cell above / to the right, however the division rounds it (``BORDER_TOLERANCE``)."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        col = np.floor((xy[:, 0] - self.origin_x) / self.resolution + BORDER_TOLERANCE).astype(np.int64)
        row = np.floor((xy[:, 1] - self.origin_y) / self.resolution + BORDER_TOLERANCE).astype(np.int64)
        return np.stack([row, col], axis=1)

    def cell_to_world(self, cells: np.ndarray) -> np.ndarray:
        """Cells (N, 2) as (row, col) -> world (N, 2) of the cell centres."""
        cells = np.asarray(cells, dtype=float).reshape(-1, 2)
        x = self.origin_x + (cells[:, 1] + 0.5) * self.resolution
        y = self.origin_y + (cells[:, 0] + 0.5) * self.resolution
        return np.stack([x, y], axis=1)

    def in_bounds(self, cells: np.ndarray) -> np.ndarray:
        """Boolean (N,) for cells (N, 2) as (row, col) inside the grid."""
        cells = np.asarray(cells).reshape(-1, 2)
        return (cells[:, 0] >= 0) & (cells[:, 0] < self.height) & (cells[:, 1] >= 0) & (cells[:, 1] < self.width)

    def contains(self, xy: np.ndarray) -> np.ndarray:
        """Boolean (N,) for world points (N, 2) inside the grid (False for any point far or not finite: compared as
        floats, never cast to a cell)."""
        m = self.world_to_map(xy) + BORDER_TOLERANCE  # (col, row), cell k covering [k, k + 1), as world_to_cell
        return (m[:, 0] >= 0) & (m[:, 0] < self.width) & (m[:, 1] >= 0) & (m[:, 1] < self.height)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """World extent (x_min, y_min, x_max, y_max) in metres."""
        w, h = self.size_m
        return (self.origin_x, self.origin_y, self.origin_x + w, self.origin_y + h)

    def world_to_map(self, xy: ArrayLike) -> np.ndarray:
        """World points (N, 2) -> continuous map coordinates (N, 2) as (col, row) in cells; cell centres at k + 0.5."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        return np.stack([(xy[:, 0] - self.origin_x) / self.resolution, (xy[:, 1] - self.origin_y) / self.resolution], 1)

    def cell_distance(self, metres: float) -> int:
        """Whole cells covering a world distance, rounded up as Nav2's ``Costmap2D::cellDistance`` does."""
        return max(0, int(np.ceil(metres / self.resolution)))

    def window(self, xy_min: tuple[float, float], xy_max: tuple[float, float]) -> Window | None:
        """The cells overlapping the world box [xy_min, xy_max], clipped to the grid; None when outside (or not finite).

        Scalar float64 arithmetic, the same as ``world_to_cell``'s (boxes are per person, per frame: numpy's call
        overhead would dominate)."""
        (x0, y0), (x1, y1) = xy_min, xy_max
        res, ox, oy, tol = self.resolution, self.origin_x, self.origin_y, BORDER_TOLERANCE
        try:  # clipped to the grid here: one Window built (a window per person and group per frame)
            col0 = max(math.floor((float(x0) - ox) / res + tol), 0)
            col1 = min(math.floor((float(x1) - ox) / res + tol) + 1, self.width)
            row0 = max(math.floor((float(y0) - oy) / res + tol), 0)
            row1 = min(math.floor((float(y1) - oy) / res + tol) + 1, self.height)
        except (ValueError, OverflowError):  # nan or inf
            return None
        return Window(row0, row1, col0, col1) if row0 < row1 and col0 < col1 else None

    @property
    def whole(self) -> Window:
        """Every cell of the grid."""
        return Window(0, self.height, 0, self.width)

    @cached_property
    def _axes(self) -> tuple[np.ndarray, np.ndarray]:
        """World x (cols,) and y (rows,) of every cell centre, computed once per grid (read-only)."""
        xs = self.origin_x + (np.arange(self.width) + 0.5) * self.resolution
        ys = self.origin_y + (np.arange(self.height) + 0.5) * self.resolution
        xs.flags.writeable = ys.flags.writeable = False
        return xs, ys

    def cell_axes(self, window: Window | None = None) -> tuple[np.ndarray, np.ndarray]:
        """World x (1, cols) and y (rows, 1) of the cell centres of the grid or a ``window``; they broadcast to
        (rows, cols) without the copies ``cell_centres`` makes. Read-only views of the grid's axes."""
        rows, cols = (window or self.whole).slices
        xs, ys = self._axes
        return xs[None, cols], ys[rows, None]

    def cell_centres(self, window: Window | None = None) -> tuple[np.ndarray, np.ndarray]:
        """World x and y of every cell centre (of the whole grid or of a ``window``), each (rows, cols)."""
        xs, ys = self.cell_axes(window)
        return np.meshgrid(xs[0], ys[:, 0])


def _check_cells(width: float, height: float) -> None:
    """LimitError when a grid of ``width`` x ``height`` cells exceeds ``Limits.map_cells``."""
    check_limit("map.size", width * height, "map_cells", "cells", f"{width:.6g} x {height:.6g} = ")


@dataclass
class Costmap2D:
    """A uint8 cost grid (rows, cols) with its geometry. Values follow Nav2 (see module constants)."""

    spec: GridSpec
    costs: np.ndarray

    def __post_init__(self) -> None:
        self.costs = np.asarray(self.costs)
        if self.costs.dtype != np.uint8 or self.costs.shape != self.spec.shape:
            raise InputError(
                f"costmap: costs must be uint8 of shape {self.spec.shape}, got {self.costs.dtype} {self.costs.shape}"
            )

    @classmethod
    def filled(cls, spec: GridSpec, value: int = FREE_SPACE) -> Costmap2D:
        return cls(spec, np.full(spec.shape, value, dtype=np.uint8))

    def copy(self) -> Costmap2D:
        return Costmap2D(self.spec, self.costs.copy())

    def cost_at(self, xy: np.ndarray) -> np.ndarray:
        """Costs (N,) at world points (N, 2); points outside the grid read NO_INFORMATION."""
        cells = self.spec.world_to_cell(xy)
        inside = self.spec.in_bounds(cells)
        out = np.full(len(cells), NO_INFORMATION, dtype=np.uint8)
        out[inside] = self.costs[cells[inside, 0], cells[inside, 1]]
        return out
