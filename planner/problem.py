"""A planning problem on a costmap, and the lookup tables every planner shares (built once per problem).

Frames and units: world frame (REP-103), metres. The robot is a disc of ``robot_radius`` whose centre moves in the
plane; the costmap follows Nav2's values (``costmap.grid``).

Validity. A robot centre is *free* in a cell when the cell is known (or ``allow_unknown``), its cost is below
INSCRIBED (253) and no LETHAL cell centre lies within ``robot_radius`` of the cell centre. The last test is an
exact Euclidean distance transform of the lethal cells (the inflation layer's,
``costmap.layers.inflation.squared_distance_to_lethal_cells``), i.e. the disc footprint checked against every lethal
cell at once; it agrees with Nav2's inscribed value when the inflation layer was built with this robot's
radius, and it still protects the robot when the costmap was inflated for a smaller one.

Planners see a slightly stricter mask, *plannable*: free cells whose eight neighbours are free too. A straight
segment whose samples, at most one cell apart, all lie in plannable cells is free over its whole length (every
point of it is within half a cell of a sample, so in that sample's cell or a neighbour). That is what lets OMPL
check motions at the costmap resolution and still return paths that pass an exact check of every point; the price
is one cell (``resolution``) of extra clearance. The start and goal cells are plannable when they are free, and so
are the free border cells beside them (a corner cell's only links inward).

Cost. Planners minimise J = integral over the path of (1 + w * c(s) / 252) ds, where c is the cost of the cell
under the robot centre (0..252) and w = ``cost_weight``: w = 0 is the shortest path; with w = 4 a metre through a
cell of cost 252 counts as five metres, so the path accepts up to four metres of detour to avoid it. This is Smac
Planner's travel-cost model (``cost_penalty``) with a larger default so that graded social zones bend the path.
The integral uses the midpoint rule on ``ceil(L / resolution)`` equal pieces of each straight segment (a length of
k cells up to rounding is k pieces; ``CostField._pieces``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TypeVar

import numpy as np
from scipy import ndimage

from costmap.grid import BORDER_TOLERANCE, INSCRIBED, LETHAL, MAX_NON_OBSTACLE, NO_INFORMATION, Costmap2D
from costmap.layers.inflation import squared_distance_to_lethal_cells
from sid.checks import check_number
from sid.errors import SidError

__all__ = [
    "CostField",
    "DEFAULT_COST_WEIGHT",
    "EndpointCollisionError",
    "MAX_COST_WEIGHT",
    "PlanningError",
    "PlanningProblem",
    "SAMPLES_PER_CALL",
    "NoPathError",
    "WalledOffError",
]

_LOOP_MAX = 40  # segment_cost sums this many samples or fewer in a Python loop, more with numpy (docs/parameters.md)
_Length = TypeVar("_Length", float, np.ndarray)  # one segment's length, or an array of them
SAMPLES_PER_CALL = 2**20
"""``CostField.segments`` prices at most about this many samples at once (a few arrays of 8 MB): a batch of long and
short segments (all pairs of a long path) is cut into chunks of similar length."""

DEFAULT_COST_WEIGHT = 4.0
"""w in J = integral of (1 + w c / 252) ds; see the module docstring. 4: on the demo scenario the smallest weight
tried that keeps the whole path beyond Hall's personal distance (1.2 m) of every member, at little extra length;
smaller weights cut through the conversation or graze it (docs/parameters.md)."""
MAX_COST_WEIGHT = 1000.0
"""The largest w accepted: a metre through the costliest free cell then costs 1001 m, past any detour a map offers;
a larger w only brings the cost sums nearer overflow (docs/parameters.md, "Planner")."""


class PlanningError(SidError, ValueError):
    """A problem that cannot be planned (start or goal outside the map or in collision, no free path); the message
    names the reason."""


class NoPathError(PlanningError):
    """A well-formed task without a solution: the start or goal in collision, or the two walled off from each other;
    the message starts with "no path: "."""


class EndpointCollisionError(NoPathError):
    """The NoPathError of a start or goal in collision; ``end`` says which ("start" or "goal"). Both are its
    ``args``, so that it pickles (a sweep's worker process) and ``type(error)(message, *error.args[1:])`` renames
    it."""

    def __init__(self, message: str, end: str) -> None:
        super().__init__(message, end)

    @property
    def end(self) -> str:
        return str(self.args[1])

    def __str__(self) -> str:
        return str(self.args[0])


class WalledOffError(NoPathError):
    """The NoPathError of a start and goal in separate free regions of the costmap (``free_regions``)."""


@dataclass(frozen=True)
class PlanningProblem:
    """Plan a disc robot from ``start`` to ``goal`` (world x, y in metres) on ``costmap``."""

    costmap: Costmap2D
    start: tuple[float, float]
    goal: tuple[float, float]
    robot_radius: float
    cost_weight: float = DEFAULT_COST_WEIGHT
    allow_unknown: bool = False

    def __post_init__(self) -> None:
        for name in ("start", "goal"):
            xy = tuple(float(v) for v in getattr(self, name))
            if len(xy) != 2 or not all(math.isfinite(v) for v in xy):
                raise PlanningError(f"{name} must be two finite world coordinates (x, y) in metres, got {xy}")
            object.__setattr__(self, name, xy)
        check_number("planning problem", "robot_radius", self.robot_radius, low=0, unit="metres", error=PlanningError)
        check_number(
            "planning problem", "cost_weight", self.cost_weight, low=0, high=MAX_COST_WEIGHT, error=PlanningError
        )


@dataclass
class CostField:
    """Precomputed validity and cost lookups for one problem, as numpy grids (rows, cols) and flat Python lists.

    ``free``: exact validity of a robot centre per cell; ``plannable``: the stricter mask planners use (module
    docstring); ``weight``: w * c / 252 per cell (0 where not free). Scalar methods take plain floats and return
    plain Python values: they are the OMPL callbacks' inner loops.
    """

    problem: PlanningProblem
    free: np.ndarray = field(init=False, repr=False)
    plannable: np.ndarray = field(init=False, repr=False)
    weight: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        problem = self.problem
        spec = problem.costmap.spec
        costs = problem.costmap.costs
        self.spec = spec
        self.resolution = spec.resolution
        self._inv_res = 1.0 / spec.resolution
        self._ox, self._oy = spec.origin_x, spec.origin_y
        self._w, self._h = spec.width, spec.height
        self._origin = np.array([[self._ox], [self._oy]])  # (2, 1), world x/y of the map's corner (m)
        self._size = np.array([[[self._w]], [[self._h]]])  # (2, 1, 1), the map's columns/rows (x/y, cells)

        lethal = costs == LETHAL
        if lethal.any():
            # Distance (m) from every cell centre to the nearest lethal cell centre, from the exact squared distance
            # in cells; capped beyond the robot's radius (or the map's diagonal), whose cells do not touch.
            reach = min(problem.robot_radius / spec.resolution, math.hypot(*spec.shape))
            cap = math.floor(reach**2) + 2.0
            clearance = np.sqrt(squared_distance_to_lethal_cells(lethal, cap), dtype=float) * spec.resolution
            touches_lethal = clearance <= problem.robot_radius
        else:
            touches_lethal = np.zeros(spec.shape, dtype=bool)
        unknown = costs == NO_INFORMATION
        blocked = (costs >= INSCRIBED) & ~unknown
        if not problem.allow_unknown:
            blocked |= unknown
        self.free = ~(blocked | touches_lethal)
        # Outside the map counts as not free, so border cells are never plannable.
        self.plannable = ndimage.binary_erosion(self.free, structure=np.ones((3, 3), bool), border_value=0)
        for xy in (problem.start, problem.goal):
            cell = spec.world_to_cell(np.array(xy))[0]
            if spec.in_bounds(cell[None])[0] and self.free[cell[0], cell[1]]:
                # The end cell, and the free cells beside it on the border: a corner cell's only links inward are
                # border cells, and a goal there (a far goal clamped to a rolling window) was walled off.
                rows = slice(max(cell[0] - 1, 0), cell[0] + 2)
                cols = slice(max(cell[1] - 1, 0), cell[1] + 2)
                near = np.zeros(spec.shape, dtype=bool)
                near[rows, cols] = True
                near[1:-1, 1:-1] = False  # border cells only
                near[cell[0], cell[1]] = True
                self.plannable |= near & self.free
        graded = np.where(unknown, MAX_NON_OBSTACLE, np.minimum(costs, MAX_NON_OBSTACLE)).astype(float)
        self.weight = np.where(self.free, problem.cost_weight * graded / MAX_NON_OBSTACLE, 0.0)
        # Scalar lookups use grids padded by one row and column (copies of the last ones), so a point on the map's
        # upper edge needs no clamping. Every lookup finds a point's cell as ``GridSpec.world_to_cell`` does,
        # floor((x - origin) / resolution + BORDER_TOLERANCE), so that a point on a cell border lands in the same cell
        # everywhere.
        self._stride = self._w + 1
        self._weight_padded = np.pad(self.weight, ((0, 1), (0, 1)), mode="edge")
        self._plannable_flat: list[bool] = np.pad(self.plannable, ((0, 1), (0, 1)), mode="edge").ravel().tolist()
        self._weight_flat: list[float] = self._weight_padded.ravel().tolist()

    def _pieces(self, length: _Length) -> _Length:
        """The number of equal pieces (a float, at least 1) the midpoint rule cuts segments of ``length`` (metres)
        into: the length in cells rounded up, where a length of k cells give or take rounding (0.8 - 0.1 m at 0.1 m
        is 7.000000000000001 cells) is k pieces. The one rule of ``segment_cost`` and ``segments_along``, so that the
        cost OMPL minimises is the cost reported and smoothed."""
        # ceil(x) as -((-x) // 1), which Python floats and numpy arrays both compute, and fast on a float (OMPL's
        # cost callback); the rounded-up count is a whole number >= 0, so adding (count < 1) makes it at least 1.
        pieces = -((1e-9 - length * self._inv_res) // 1.0)
        return pieces + (pieces < 1.0)

    # ---- scalar lookups (OMPL callbacks) -------------------------------------------------------------------------
    def is_plannable(self, x: float, y: float) -> bool:
        """Whether a robot centre at world (x, y), inside the map, may be used by a planner."""
        res, tol = self.resolution, BORDER_TOLERANCE
        row, col = math.floor((y - self._oy) / res + tol), math.floor((x - self._ox) / res + tol)
        return self._plannable_flat[row * self._stride + col]

    def segment_cost(self, x0: float, y0: float, x1: float, y1: float) -> float:
        """J of the straight segment (x0, y0) -> (x1, y1) (metres of weighted length), both ends inside the map."""
        dx, dy = x1 - x0, y1 - y0
        length = math.hypot(dx, dy)
        n = int(self._pieces(length))
        # Midpoint i at t = (i + 0.5) / n, to a cell of the padded grids as ``GridSpec.world_to_cell`` does.
        res, ox, oy, tol = self.resolution, self._ox, self._oy, BORDER_TOLERANCE
        if n > _LOOP_MAX:  # numpy's fixed overhead pays off on long segments
            ts = np.arange(0.5, n) / n  # (i + 0.5) / n
            # Offsets >= 0 inside the map: truncation is the floor.
            rows = ((y0 + ts * dy - oy) / res + tol).astype(np.intp)
            cols = ((x0 + ts * dx - ox) / res + tol).astype(np.intp)
            total = float(self._weight_padded[rows, cols].sum())
        else:
            weight, stride, floor = self._weight_flat, self._stride, math.floor
            total = 0.0
            for i in range(n):
                t = (i + 0.5) / n
                total += weight[floor((y0 + t * dy - oy) / res + tol) * stride + floor((x0 + t * dx - ox) / res + tol)]
        return length * (1.0 + total / n)

    # ---- vectorised lookups (planners' post-processing, validation, metrics) -------------------------------------
    def cells(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(rows, cols, inside) for world points (N, 2); rows/cols are clipped into the grid."""
        cells = self.spec.world_to_cell(xy)
        inside = self.spec.in_bounds(cells)
        rows = np.clip(cells[:, 0], 0, self._h - 1)
        cols = np.clip(cells[:, 1], 0, self._w - 1)
        return rows, cols, inside

    def free_at(self, xy: np.ndarray) -> np.ndarray:
        """Exact validity (N,) of robot centres at world points (N, 2); outside the map is not free."""
        rows, cols, inside = self.cells(xy)
        return self.free[rows, cols] & inside

    def segments(self, p: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """J (M,) of straight segments p[i] -> q[i] (each (M, 2)) and whether each is plannable over its length.

        Same midpoint rule as ``segment_cost``; plannability is checked at the midpoints and the piece ends
        (spacing at most half a cell). Ends that are not finite numbers give a NaN or infinite J (the segment's
        length) and a segment that is not plannable.
        """
        p = np.asarray(p, dtype=float).reshape(-1, 2)
        q = np.asarray(q, dtype=float).reshape(-1, 2)
        if len(p) == 0:
            return np.zeros(0), np.zeros(0, bool)
        return self.segments_xy(np.ascontiguousarray(p.T), np.ascontiguousarray(q.T))

    def segments_xy(self, p: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``segments`` with the ends given coordinate-major: p, q (2, M), M >= 1 (world frame, metres)."""
        d = q - p
        return self.segments_along(p, d, np.hypot(d[0], d[1]))

    def segments_along(self, p: np.ndarray, d: np.ndarray, length: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``segments_xy`` from the segments' starts p (2, M), offsets d = q - p (2, M) and lengths
        ``np.hypot(d[0], d[1])`` (M,), M >= 1 (world frame, metres): for the smoother's inner loop, which has them
        already. ``segments_xy`` uses q only through d, so the values are the same.

        Sample k of a segment of n pieces (k = 0 .. 2n: even k piece ends, odd k the midpoints the cost uses) sits in
        row k of (K, M) arrays (samples past a segment's end repeat its end), at t = k / (2n) along it, in the cell
        ``GridSpec.world_to_cell`` gives (as ``segment_cost``); each segment's cost sums its midpoints in order of k,
        and numpy's inner loops run over segments, not over two coordinates.
        """
        if not math.isfinite(float(length.max())):  # NaN or infinite ends: J is the length (NaN or inf), not plannable
            finite = np.isfinite(length)
            cost, ok = length.copy(), np.zeros(len(length), dtype=bool)
            if finite.any():
                cost[finite], ok[finite] = self.segments_along(p[:, finite], d[:, finite], length[finite])
            return cost, ok
        pieces = self._pieces(length)
        last = 2.0 * pieces  # each segment's end sample
        width = int(last.max()) + 2  # one spare sample: each segment's slice of samples ends inside its row
        if width * len(last) > SAMPLES_PER_CALL and len(last) > 1:
            return self._segments_in_chunks(p, d, length, last)
        t = np.minimum(np.arange(width, dtype=float)[:, None], last) / last  # (K, M), 0 .. 1 along each segment
        xy = t * d[:, None, :]  # (2, K, M): world points, then cells as GridSpec.world_to_cell finds them
        xy += p[:, None, :]
        xy -= self._origin[:, :, None]
        xy /= self.resolution
        xy += BORDER_TOLERANCE
        size = self._size
        # The samples run monotonically from one end (row 0) to the other (row K - 1): both inside, all inside.
        ends = xy[:, :: width - 1]
        if np.count_nonzero((ends >= 0.0) & (ends < size)) == ends.size:
            cells = xy.astype(np.intp)  # truncation is floor for offsets >= 0
            inside = None
        else:  # outside samples read the nearest border cell and are not plannable
            cells = np.floor(xy).astype(np.intp)
            inside = ((cells >= 0) & (cells < size)).all(axis=0)
            np.clip(cells, 0, size - 1, out=cells)
        flat = cells[1] * self._w
        flat += cells[0]
        plannable = self.plannable.ravel().take(flat)
        ok = (plannable if inside is None else plannable & inside).all(axis=0)
        weights = self.weight.ravel().take(flat.T)  # (M, K): one row per segment
        weights[:, 0::2] = 0.0  # midpoints only
        # Per segment the slice [row start, row start + last + 1) of the flat array; the slices between are dropped.
        bounds = np.empty((len(length), 2), dtype=np.intp)
        bounds[:, 0] = np.arange(0, len(length) * width, width)
        bounds[:, 1] = bounds[:, 0] + (last + 1.0).astype(np.intp)
        cost = length * (1.0 + np.add.reduceat(weights.ravel(), bounds.ravel())[0::2] / pieces)
        return cost, ok

    def _segments_in_chunks(
        self, p: np.ndarray, d: np.ndarray, length: np.ndarray, last: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """``segments_along`` of many segments of unequal length (``last``: 2 x their pieces) in chunks of similar
        length, each within ``SAMPLES_PER_CALL`` samples: memory stays bounded and short segments do not pay for the
        longest one's row. The same values (each segment's samples and sum do not depend on the others)."""
        order = np.argsort(last, kind="stable")
        width = last[order] + 2.0  # a chunk's row width is that of its last (longest) segment
        cost, ok = np.empty(len(last)), np.empty(len(last), dtype=bool)
        start = 0
        while start < len(order):
            fits = width[start:] * np.arange(1, len(order) - start + 1) <= SAMPLES_PER_CALL  # True..., then False...
            stop = start + (len(fits) if fits.all() else max(1, int(np.argmin(fits))))
            chunk = order[start:stop]
            cost[chunk], ok[chunk] = self.segments_along(p.take(chunk, axis=1), d.take(chunk, axis=1), length[chunk])
            start = stop
        return cost, ok

    def path_cost(self, path: np.ndarray) -> float:
        """J of a polyline (N, 2)."""
        path = np.asarray(path, dtype=float).reshape(-1, 2)
        if len(path) < 2:
            return 0.0
        return float(self.segments(path[:-1], path[1:])[0].sum())
