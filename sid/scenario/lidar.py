"""A simulated 360-degree 2D LiDAR: exact ranges against a scenario's obstacles, people and a static map.

Frames: the sensor pose (x, y, yaw) is in the world frame (REP-103, metres, radians); beam angles are relative
to the sensor's yaw, counter-clockwise, as in ``sensor_msgs/LaserScan``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from costmap.grid import BORDER_TOLERANCE, LETHAL, Costmap2D
from costmap.scan import LaserScan
from sid.checks import check_number
from sid.errors import InputError
from sid.perception.people import Person
from sid.scenario.obstacles import BoxObstacle, CircleObstacle, Obstacle, SegmentObstacle

__all__ = ["simulate_scan"]


_TESTS_PER_BLOCK = 1_000_000
"""Ray tests (beam x edge or circle) per block of beams: the arrays of one block stay tens of megabytes, whatever
the number of walls (``Limits.scan_edges`` bounds the time)."""


def _segments(obstacles: Sequence[Obstacle]) -> tuple[np.ndarray, np.ndarray]:
    """Start and end points (S, 2) of every straight piece of walls and boxes."""
    starts, ends = [], []
    for ob in obstacles:
        if isinstance(ob, SegmentObstacle):
            pts = np.asarray(ob.points, dtype=float)
            starts.append(pts[:-1])
            ends.append(pts[1:])
        elif isinstance(ob, BoxObstacle):
            (x0, y0), (x1, y1) = ob.min, ob.max
            corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)
            starts.append(corners)
            ends.append(np.roll(corners, -1, axis=0))
    if not starts:
        return np.zeros((0, 2)), np.zeros((0, 2))
    return np.concatenate(starts), np.concatenate(ends)


def _ray_segment_ranges(origin: np.ndarray, dirs: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Nearest positive hit distance (B,) of rays origin + t * dirs against segments a-b (inf if none)."""
    if len(a) == 0:
        return np.full(len(dirs), np.inf)
    e = b - a  # (S, 2)
    w = a - origin  # (S, 2)
    denom = dirs[:, :1] * e[:, 1] - dirs[:, 1:] * e[:, 0]  # (B, S): cross(d, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[:, 0] * e[:, 1] - w[:, 1] * e[:, 0]) / denom  # cross(w, e) / cross(d, e)
        u = (w[:, 0] * dirs[:, 1:] - w[:, 1] * dirs[:, :1]) / denom  # cross(w, d) / cross(d, e)
    ok = (np.abs(denom) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1)
    return np.where(ok, t, np.inf).min(axis=1)


def _ray_circle_ranges(origin: np.ndarray, dirs: np.ndarray, centres: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """Nearest positive hit distance (B,) of unit rays against circles (inf if none)."""
    if len(centres) == 0:
        return np.full(len(dirs), np.inf)
    w = centres - origin  # (C, 2)
    proj = dirs @ w.T  # (B, C): d . w
    disc = proj**2 - (np.einsum("ij,ij->i", w, w) - radii**2)
    root = np.sqrt(np.maximum(disc, 0.0))
    near, far = proj - root, proj + root
    t = np.where(near > 0, near, far)  # from inside a circle the exit point is the first surface hit
    return np.where((disc >= 0) & (t > 0), t, np.inf).min(axis=1)


def _grid_ranges(origin: np.ndarray, dirs: np.ndarray, grid: Costmap2D, range_max: float) -> np.ndarray:
    """Distance (B,) along unit rays to the first LETHAL cell of ``grid`` (inf if none within range_max).

    A map is cells, not shapes, so rays are sampled every half cell (all beams at once); a ray can slip between
    two lethal cells that touch only at a corner.
    """
    spec = grid.spec
    step = spec.resolution / 2
    t = np.arange(1, int(np.ceil(range_max / step)) + 1) * step
    m = spec.world_to_map(origin[None])[0] + BORDER_TOLERANCE  # cells as GridSpec.world_to_cell finds them
    cols = np.floor(m[0] + dirs[:, :1] * (t / spec.resolution)).astype(np.int64)
    rows = np.floor(m[1] + dirs[:, 1:] * (t / spec.resolution)).astype(np.int64)
    inside = (rows >= 0) & (rows < spec.height) & (cols >= 0) & (cols < spec.width)
    hit = np.zeros(rows.shape, dtype=bool)
    hit[inside] = grid.costs[rows[inside], cols[inside]] == LETHAL
    first = hit.argmax(axis=1)
    return np.where(hit.any(axis=1), t[first], np.inf)


def simulate_scan(
    pose: tuple[float, float, float],
    obstacles: Sequence[Obstacle],
    people: Sequence[Person] = (),
    *,
    beams: int = 720,
    range_max: float = 10.0,
    body_radius: float = 0.2,
    static: Costmap2D | None = None,
) -> LaserScan:
    """A 360-degree scan from ``pose`` (world x, y, yaw) against walls, boxes, circles and people's bodies.

    Exact ray/segment and ray/circle intersections for all beams at once (no grid marching), in numpy: a geometry
    library would build one line object per beam. People are circles
    of ``body_radius`` metres (their cross-section at the scan height). ``static``: a static map whose LETHAL
    cells the beams hit too. Beams that hit nothing within ``range_max`` read ``inf``.
    """
    if beams < 1:
        raise InputError(f"lidar.beams must be >= 1, got {beams}")
    check_number("lidar", "range_max", range_max, low=0, low_open=True, unit="metres")
    pose_t = tuple(float(v) for v in pose)
    if len(pose_t) != 3 or not np.isfinite(pose_t).all():
        raise InputError(f"scan pose must be a finite (x, y, yaw), got {pose}")
    increment = 2 * np.pi / beams
    scan = LaserScan(np.zeros(beams), -np.pi, increment, range_max, pose_t)
    origin, dirs = np.asarray(pose_t[:2]), scan.directions

    a, b = _segments(obstacles)
    circles = [(ob.center, ob.radius) for ob in obstacles if isinstance(ob, CircleObstacle)]
    circles += [((p.x, p.y), body_radius) for p in people]
    centres = np.array([c for c, _ in circles], dtype=float).reshape(-1, 2)
    if not np.isfinite(centres).all():
        raise InputError("simulate_scan: a circle obstacle or a person has a non-finite position")
    radii = np.array([r for _, r in circles], dtype=float)

    ranges = np.empty(beams)
    block = max(1, _TESTS_PER_BLOCK // max(len(a) + len(radii), 1))  # beams per block: bounded (beams, edges) arrays
    for k in range(0, beams, block):
        d = dirs[k : k + block]
        ranges[k : k + block] = np.minimum(
            _ray_segment_ranges(origin, d, a, b), _ray_circle_ranges(origin, d, centres, radii)
        )
    if static is not None:
        np.minimum(ranges, _grid_ranges(origin, dirs, static, range_max), out=ranges)
    ranges[ranges > range_max] = np.inf
    return LaserScan(ranges, -np.pi, increment, range_max, pose_t)
