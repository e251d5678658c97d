"""The LiDAR base layer: Nav2's obstacle layer for 2D scans (clear along each beam, then mark its hit).

For every beam with a valid reading, the cells on the line from the sensor cell to the hit cell (the hit cell
excluded) become FREE, up to ``raytrace_max_range``; then every hit within ``obstacle_max_range`` marks its cell
LETHAL. Clearing runs over all beams before marking, as in Nav2, so a beam grazing a wall never erases another
beam's hit. Beams with no return (``inf``) clear out to ``raytrace_max_range`` when ``clear_on_no_return`` is set
(Nav2's ``inf_is_valid``) and never mark; invalid beams (``nan``) are ignored.

Lines are traced with a rounded DDA over integer cells (one cell per step along the major axis: the cells of
Bresenham's algorithm up to tie-breaking), for all beams at once in numpy rather than cell by cell (line drawing
in OpenCV or scikit-image draws one line per call, 720 Python calls per scan).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from costmap.combine import CombinationMethod
from costmap.grid import FREE_SPACE, LETHAL, NO_INFORMATION, GridSpec, Window, union
from costmap.layer import Layer, LayerInputs
from costmap.scan import LaserScan
from sid.checks import check_number, check_numbers


@dataclass(frozen=True)
class ObstacleParams:
    """Marking/clearing ranges (metres) and unknown-space tracking.

    Nav2's defaults are obstacle_max_range 2.5 and raytrace_max_range 3.0, sized for a local costmap refreshed
    many times a second. Here one scan from the robot's start pose builds the whole map, so both default to the
    simulated LiDAR's 10 m range.

    track_unknown_space (default False, Nav2's costmap default): cells no beam has crossed start FREE. With True
    (as Nav2's global costmap is usually configured) they stay NO_INFORMATION (255); after a single scan that
    leaves unknown wedges behind every obstacle and, beyond ~5.7 m at 720 beams and 5 cm cells, unknown stripes
    between diverging beams, so the map would depend on beam aliasing rather than on the scene.
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
    """Flat indices of the cells on the lines origin -> ends (world, (M, 2), finite), end cells excluded, in the grid.

    float32 arithmetic, for speed (docs/parameters.md): exact enough for cell indices below 2^20; it changes only
    which cell a tie (exactly half-way) rounds to.
    """
    if len(ends) == 0:
        return np.zeros(0, dtype=np.int64)
    c0 = spec.world_to_cell(origin)[0]
    delta = (spec.world_to_cell(ends) - c0).astype(np.float32)  # (M, 2) as (row, col)
    steps = np.abs(delta).max(axis=1)
    n = int(steps.max())
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    k = np.arange(n, dtype=np.float32)[None, :]
    frac = k / np.maximum(steps, 1)[:, None]  # (M, n)
    rows = (c0[0] + np.rint(frac * delta[:, :1])).astype(np.int32)
    cols = (c0[1] + np.rint(frac * delta[:, 1:])).astype(np.int32)
    keep = (k < steps[:, None]) & (rows >= 0) & (rows < spec.height) & (cols >= 0) & (cols < spec.width)
    return rows[keep].astype(np.int64) * spec.width + cols[keep]


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

    def __init__(self, spec: GridSpec, params: ObstacleParams | None = None, people_clear_radius: float = 0.0) -> None:
        check_number("lidar layer", "people_clear_radius", people_clear_radius, low=0, unit="metres")
        self.params = params or ObstacleParams()
        super().__init__(spec, self.params.default_value)
        self.people_clear_radius = float(people_clear_radius)

    def update(self, inputs: LayerInputs, changed: Window | None) -> Window | None:
        """Apply the scan (if any), then clear the people's marks."""
        scanned = None if inputs.scan is None else self.apply_scan(inputs.scan)
        if self.people_clear_radius == 0:
            return scanned
        people = np.array([(p.x, p.y) for p in inputs.people], dtype=float)
        return union(scanned, self.clear_discs(people, self.people_clear_radius))

    def apply_scan(self, scan: LaserScan) -> Window | None:
        """Clear along every beam, then mark every hit (Nav2's raytraceFreespace + marking); returns the window."""
        p = self.params
        origin = np.asarray(scan.pose[:2])
        if not self.spec.contains(origin[None])[0]:
            raise ValueError(f"scan: sensor at ({origin[0]:.2f}, {origin[1]:.2f}) is outside the costmap")
        r = scan.valid_ranges()
        dirs = scan.directions
        clear_to = np.where(np.isinf(r), p.raytrace_max_range if p.clear_on_no_return else np.nan, r)
        clearing = np.isfinite(clear_to)
        clear_len = np.minimum(clear_to[clearing], p.raytrace_max_range)
        ends = origin + dirs[clearing] * clear_len[:, None]
        self.costs.ravel()[trace_cells(self.spec, origin, ends)] = FREE_SPACE

        with np.errstate(invalid="ignore"):
            marking = np.isfinite(r) & (r >= p.obstacle_min_range) & (r <= p.obstacle_max_range)
        hit_xy = origin + dirs[marking] * r[marking, None]
        hits = self.spec.world_to_cell(hit_xy)
        hits = hits[self.spec.in_bounds(hits)]
        self.costs[hits[:, 0], hits[:, 1]] = LETHAL
        return self.spec.window_around(np.vstack([origin[None], ends, hit_xy]))

    def clear_discs(self, centres: np.ndarray, radius: float) -> Window | None:
        """Turn LETHAL marks whose cell centre lies within ``radius`` metres of any centre (N, 2) into FREE; returns
        the window of the discs."""
        centres = np.asarray(centres, dtype=float).reshape(-1, 2)
        cleared = None
        for cx, cy in centres:
            window = self.spec.window((cx - radius, cy - radius), (cx + radius, cy + radius))
            if window is None:
                continue
            xs, ys = self.spec.cell_axes(window)
            view = self.costs[window.slices]
            inside = ((xs - cx) ** 2 + (ys - cy) ** 2 <= radius**2) & (view == LETHAL)
            view[inside] = FREE_SPACE
            cleared = window.union(cleared)
        return cleared
