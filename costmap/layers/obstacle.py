"""The LiDAR base layer: Nav2's obstacle layer for 2D scans (clear along each beam, then mark its hit).

For every beam with a valid reading, the cells on the line from the sensor cell to the hit cell (the hit cell
excluded) become FREE, up to ``raytrace_max_range``; then every hit within ``obstacle_max_range`` marks its cell
LETHAL. Clearing runs over all beams before marking, as in Nav2, so a beam grazing a wall never erases another
beam's hit. Beams with no return (``inf``) clear out to ``raytrace_max_range`` when ``clear_on_no_return`` is set
(Nav2's ``inf_is_valid``) and never mark; invalid beams (``nan``) are ignored.

Lines are traced with a rounded DDA over integer cells (one cell per step along the major axis: the cells of
Bresenham's algorithm up to tie-breaking), for all beams at once in numpy rather than cell by cell (line drawing
in OpenCV or scikit-image draws one line per call, 720 Python calls per scan). The layer keeps each beam's cells
and, while the sensor stays in its cell, traces again only the beams whose end cell moved (``_BeamCells``). While
few beams move (a standing robot, people walking) it also counts the beams crossing each cell and writes only what
clearing every beam would change: the cells of the beams traced again, and the last scan's hits that some beam now
crosses (every other beam cell was cleared by the last scan already); a test checks the grid against clearing every
beam, with the sensor standing, turning and moving.

Each update reports the window of the cells whose value changed, not the window the scan covers: a scan of a scene
that did not change (people's marks aside, which are cleared) makes the costmap recombine nothing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from costmap.combine import CombinationMethod
from costmap.grid import FREE_SPACE, LETHAL, NO_INFORMATION, GridSpec, Window, nonzero_cells
from costmap.layer import Input, Layer, LayerInputs
from costmap.layers.social import PEOPLE
from costmap.scan import LaserScan
from sid.checks import check_number, check_numbers
from sid.errors import InputError

__all__ = ["SCAN", "ObstacleLayer", "ObstacleParams", "trace_cells"]

SCAN: Input[LaserScan | None] = Input("scan", None)
"""The frame's 2D scan, in the costmap's frame (None: no scan this frame): applied by the obstacle (LiDAR) layer."""


@dataclass(frozen=True)
class ObstacleParams:
    """Marking/clearing ranges (metres) and unknown-space tracking.

    Nav2's defaults are obstacle_max_range 2.5 and raytrace_max_range 3.0, sized for a local costmap refreshed
    many times a second. Here one scan from the robot's start pose builds the whole map, so both default to the
    simulated LiDAR's 10 m range.

    track_unknown_space (default False, Nav2's costmap default): cells no beam has crossed start FREE. With True
    (as Nav2's global costmap is usually configured) they stay NO_INFORMATION (255); after a single scan that
    leaves unknown wedges behind every obstacle and, beyond the range where neighbouring beams lie more than a cell
    apart (resolution / angle increment; docs/scenario.md), unknown stripes between diverging beams, so the map would
    depend on beam aliasing rather than on the scene.
    """

    obstacle_max_range: float = 10.0
    obstacle_min_range: float = 0.0
    raytrace_max_range: float = 10.0
    track_unknown_space: bool = False
    clear_on_no_return: bool = True

    def __post_init__(self) -> None:
        ranges = ("obstacle_max_range", "obstacle_min_range", "raytrace_max_range")
        check_numbers("obstacle", self, ranges, low=0, unit="metres")

    @property
    def default_value(self) -> int:
        return NO_INFORMATION if self.track_unknown_space else FREE_SPACE


def trace_cells(spec: GridSpec, origin: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Flat indices of the cells on the lines origin -> ends (world, (M, 2), finite), end cells excluded, in the grid
    (``_trace_lines``)."""
    c0 = spec.world_to_cell(origin)[0]
    delta = spec.world_to_cell(ends) - c0
    flat, keep = _trace_lines(spec, c0, delta, _longest(delta))
    return flat[keep]


def _longest(delta: np.ndarray) -> int:
    """Steps of the longest line of ``delta`` (cells, (M, 2) as (row, col)): its length along its major axis."""
    return int(np.abs(delta).max(initial=0))


def _trace_lines(spec: GridSpec, c0: np.ndarray, delta: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The cells of the lines from cell ``c0`` (row, col) to cells ``c0 + delta`` ((M, 2)), end cells excluded, as
    flat indices (M, n) and whether each is on its line and in the grid (M, n); ``n``: at least the longest line.

    Step k of a line of ``steps`` cells (its length along its major axis) is c0 + rint(k / steps * delta), in float32
    for speed (docs/parameters.md): exact enough for cell indices below 2^20; it changes only which cell a tie
    (exactly half-way) rounds to.
    """
    delta = delta.astype(np.float32)
    steps = np.abs(delta).max(axis=1, initial=0)
    k = np.arange(n, dtype=np.float32)[None, :]
    frac = k / np.maximum(steps, 1)[:, None]  # (M, n)
    rows = np.rint(frac * delta[:, :1]).astype(np.int32) + np.int32(c0[0])  # integer adds: no float64 pass
    cols = np.rint(frac * delta[:, 1:]).astype(np.int32) + np.int32(c0[1])
    # in the grid: 0 <= index < size in one comparison each (a negative index reads as a huge unsigned one)
    keep = (k < steps[:, None]) & (rows.view(np.uint32) < spec.height) & (cols.view(np.uint32) < spec.width)
    return rows.astype(np.int64) * spec.width + cols, keep


_BEYOND_HIT = 1e-4
"""Cells a hit is taken along its beam before its cell is found: a hit on a surface that lies on a cell border (a
wall at y = 0.8 m on 0.05 m cells) computes as 0.7999... from one side, and would mark the free cell before the wall
instead of the wall's cell (``known_map`` puts a border in the cell above or to the right, the cell a beam from below
enters). Far below any sensor's resolution, far above the rounding of origin + range x direction, and above
``costmap.grid.BORDER_TOLERANCE``, so that a beam from above marks the cell below the border."""
_PAIRS_PER_CHUNK = 2**20
"""``_marks_near`` tests at most this many (mark, person) pairs at once (a few MB of float64)."""


_INCREMENTAL_SHARE = 0.5
"""A scan whose beams' end cells moved for at most this share of the beams (the sensor in the same cell) is written
incrementally (``_BeamCells``); otherwise whole."""

_ONE = np.int32(1)
"""The coverage counts' step: a numpy scalar of their dtype keeps ``np.add.at`` on its fast path (a Python int is
much slower)."""


class _BeamCells:
    """The cells the current scan's beams cross, kept beam by beam. A new scan from the same sensor cell traces again
    only the beams whose end cell moved (a line's cells depend only on its two end cells); while the sensor stays in
    its cell, the number of beams crossing each cell is kept too (built when first needed: a moving sensor traces
    every beam again anyway)."""

    def __init__(self, spec: GridSpec) -> None:
        self.spec = spec
        self.origin = np.full(2, -1)  # the sensor's cell (row, col)
        self.delta = np.zeros((0, 2), dtype=np.int64)  # (M, 2) end cell - sensor cell, by beam
        self.flat = np.zeros((0, 0), dtype=np.int64)  # (M, n) as ``_trace_lines``
        self.keep = np.zeros((0, 0), dtype=bool)
        self._coverage: np.ndarray | None = None  # beams crossing each cell (flat index, int32); None: not built

    def update(self, origin: np.ndarray, ends: np.ndarray) -> tuple[np.ndarray, bool]:
        """Take the lines origin -> ends (world, (M, 2), finite) as the current beams. Returns the flat indices of
        the cells of the beams traced again (``trace_cells``' cells of those beams, end cells excluded) and whether
        every beam was traced again (the sensor moved to another cell, the number of beams changed, or more than
        ``_INCREMENTAL_SHARE`` of the beams moved)."""
        c0 = self.spec.world_to_cell(origin)[0]
        delta = self.spec.world_to_cell(ends) - c0
        same_sensor = np.array_equal(c0, self.origin) and delta.shape == self.delta.shape
        redo = np.flatnonzero((delta != self.delta).any(axis=1)) if same_sensor else np.arange(0)
        # Counting beams pays while few of them move (a standing robot, people walking); when most move (the robot
        # moves within its cell) the scan is written whole, as after a move to another cell.
        if same_sensor and len(redo) <= _INCREMENTAL_SHARE * len(delta):
            np.subtract.at(self.coverage, self.flat[redo][self.keep[redo]], _ONE)
            everything = False
        else:
            redo = np.arange(len(delta))
            self._coverage = None
            self.flat = np.zeros((len(delta), 0), dtype=np.int64)
            self.keep = np.zeros((len(delta), 0), dtype=bool)
            everything = True
        n = _longest(delta[redo])
        if n > self.flat.shape[1]:  # longer lines than any kept: widen (the new steps are off every line)
            grow = ((0, 0), (0, n - self.flat.shape[1]))
            self.flat, self.keep = np.pad(self.flat, grow), np.pad(self.keep, grow)
        flat, keep = _trace_lines(self.spec, c0, delta[redo], self.flat.shape[1])
        self.flat[redo], self.keep[redo] = flat, keep
        self.origin, self.delta = c0, delta
        traced = flat[keep]
        if self._coverage is not None:
            np.add.at(self._coverage, traced, _ONE)
        return traced, everything

    @property
    def coverage(self) -> np.ndarray:
        """How many current beams cross each cell (flat index), built from the kept cells when first asked for."""
        if self._coverage is None:
            cells = self.flat[self.keep]
            self._coverage = np.bincount(cells, minlength=self.spec.width * self.spec.height).astype(np.int32)
        return self._coverage


class _ScanMarks(NamedTuple):
    """What one scan writes: the cells to clear (flat indices: those of the beams traced again, and the last scan's
    hits that a beam now crosses) and the cells its hits mark LETHAL ((K, 2) as (row, col))."""

    cleared: np.ndarray
    hits: np.ndarray


class ObstacleLayer(Layer):
    """A persistent grid of LiDAR marks: FREE where beams passed, LETHAL at hits, the default elsewhere.

    People. With ``people_clear_radius`` > 0 (m; set when another layer draws the people), the marks within that
    radius of the current people are cleared after every update: they are the people's, not the map's, so a person
    is counted once and one who moves leaves nothing behind, even where no new beam reaches. A mark at an old
    position that a new scan hits again stays (something is really there). With 0 (no recognition) people are plain
    obstacles, cleared only by beams, as in Nav2.
    """

    name = "lidar"
    combination: CombinationMethod = "max"
    reads = (SCAN, PEOPLE)

    def __init__(self, spec: GridSpec, params: ObstacleParams | None = None, people_clear_radius: float = 0.0) -> None:
        check_number("lidar layer", "people_clear_radius", people_clear_radius, low=0, unit="metres")
        self.params = params or ObstacleParams()
        super().__init__(spec, self.params.default_value)
        self.people_clear_radius = float(people_clear_radius)
        self._beams = _BeamCells(spec)
        self._hits = np.zeros(0, dtype=np.int64)  # the last scan's hit cells (flat indices)

    def update(self, inputs: LayerInputs, changed: Window | None) -> Window | None:
        """Apply the ``SCAN`` (if any), then clear the marks of the ``PEOPLE``; returns the window of the cells whose
        value changed (a new scan of an unchanged scene changes none: the costmap recombines nothing for it)."""
        scan = inputs.get(SCAN)
        marks = None if scan is None else self._scan_marks(scan)
        people = [(p.x, p.y) for p in inputs.get(PEOPLE)] if self.people_clear_radius > 0 else []
        return self._apply(marks, np.array(people, dtype=float).reshape(-1, 2))

    def apply_scan(self, scan: LaserScan) -> Window | None:
        """Clear along every beam, then mark every hit (Nav2's raytraceFreespace + marking); returns the window of
        the cells whose value changed."""
        return self._apply(self._scan_marks(scan), np.zeros((0, 2)))

    def _apply(self, scan: _ScanMarks | None, people: np.ndarray) -> Window | None:
        """Write a scan's marks (if any), then clear the marks within ``people_clear_radius`` of the people (world,
        (N, 2)); returns the window of the cells whose value changed.

        Only the cells written are compared, before and after (an index may repeat): the scan's cells, and the marks
        near the people, looked for before the scan is written among the LETHAL cells and the scan's hits."""
        hits = np.zeros(0, dtype=np.int64) if scan is None else scan.hits[:, 0] * self.spec.width + scan.hits[:, 1]
        near = self._marks_near(people, self.people_clear_radius, hits)
        written = near if scan is None else np.concatenate((scan.cleared, hits, near))
        costs = self.costs.ravel()
        before = costs[written]
        if scan is not None:
            costs[scan.cleared] = FREE_SPACE
            costs[hits] = LETHAL
            self._hits = hits
        costs[near[costs[near] == LETHAL]] = FREE_SPACE
        rows, cols = np.divmod(written[costs[written] != before], self.spec.width)
        if len(rows) == 0:
            return None
        return Window(int(rows.min()), int(rows.max()) + 1, int(cols.min()), int(cols.max()) + 1)

    def _scan_marks(self, scan: LaserScan) -> _ScanMarks:
        """What a scan writes (nothing written yet; the beams' cells are taken as the current ones).

        Clearing every beam's cells and then marking the hits, as Nav2 does, leaves the cells of a beam that did not
        move FREE already (the last scan cleared them) but for the last scan's hits that such a beam crosses: only
        those, and the cells of the beams traced again, are written."""
        p = self.params
        origin = np.asarray(scan.pose[:2])
        if self.spec.window(scan.pose[:2], scan.pose[:2]) is None:  # its cell is outside (scalar: cheaper here)
            raise InputError(f"scan: sensor at ({origin[0]:.2f}, {origin[1]:.2f}) is outside the costmap")
        r = scan.valid_ranges()
        dirs = scan.directions
        beyond = r + _BEYOND_HIT * self.spec.resolution  # where the beam's cells end: the surface's far side
        clear_to = np.where(np.isinf(r), p.raytrace_max_range if p.clear_on_no_return else np.nan, beyond)
        clearing = np.isfinite(clear_to)
        clear_len = np.minimum(clear_to[clearing], p.raytrace_max_range)
        ends = origin + dirs[clearing] * clear_len[:, None]
        with np.errstate(invalid="ignore"):
            marking = np.isfinite(r) & (r >= p.obstacle_min_range) & (r <= p.obstacle_max_range)
        hit_xy = origin + dirs[marking] * beyond[marking, None]
        hits = self.spec.world_to_cell(hit_xy)
        hits = hits[self.spec.in_bounds(hits)]
        traced, everything = self._beams.update(origin, ends)
        if everything:  # every beam's cells
            return _ScanMarks(traced, hits)
        crossed = self._hits[self._beams.coverage[self._hits] > 0]
        return _ScanMarks(np.concatenate((traced, crossed)), hits)

    def _marks_near(self, centres: np.ndarray, radius: float, also: np.ndarray) -> np.ndarray:
        """Flat indices of the cells, among the LETHAL ones and those of ``also`` (flat indices), whose centre lies
        within ``radius`` metres of any centre (N, 2); they may repeat.

        Only those cells are tested (against every centre at once): there are few, and discs are many small windows.
        """
        window = self._discs_window(centres, radius)
        if window is None:
            return np.zeros(0, dtype=np.int64)
        rows, cols = nonzero_cells(self.costs[window.slices] == LETHAL)
        cells = np.concatenate(((rows + window.row0) * self.spec.width + cols + window.col0, also))
        rows, cols = np.divmod(cells, self.spec.width)
        xs, ys = self.spec.cell_axes()
        inside = np.zeros(len(cells), dtype=bool)
        chunk = max(1, _PAIRS_PER_CHUNK // len(centres))  # (cells, centres) pairs at a time: memory stays bounded
        for start in range(0, len(cells), chunk):
            r, c = rows[start : start + chunk], cols[start : start + chunk]
            dx, dy = xs[0, c, None] - centres[:, 0], ys[r, 0, None] - centres[:, 1]  # (cells, centres)
            inside[start : start + chunk] = (dx**2 + dy**2 <= radius**2).any(axis=1)
        return cells[inside]

    def _discs_window(self, centres: np.ndarray, radius: float) -> Window | None:
        """The cells of the bounding box of discs of ``radius`` metres around world centres (N, 2); None: none."""
        if len(centres) == 0:
            return None
        return self.spec.window(tuple(centres.min(axis=0) - radius), tuple(centres.max(axis=0) + radius))
