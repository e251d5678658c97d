"""The camera's field of view on the ground: where the tracker can expect to see people.

A track whose predicted position lies outside the view was not missed by the detector, it was not looked at, so
the tracker keeps it longer (``TrackerParams.out_of_view_timeout``) than one missed in plain view; so it does a track
that a camera's cone sees behind someone nearer (``ViewCone.behind``): the camera looked, but at the person in front.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from sid.checks import check_number, check_numbers
from sid.errors import InputError
from sid.perception.camera import Calibration
from sid.perception.mount import CameraMount
from sid.perception.robot_pose import RobotPose

if TYPE_CHECKING:  # annotations only: the pipeline is the caller's
    from sid.perception.frame import Frame
    from sid.perception.pipeline import Pipeline

__all__ = ["View", "ViewCone", "ViewRegion", "camera_fov", "camera_view_cone", "pipeline_view", "scene_view"]


@dataclass(frozen=True)
class ViewCone:
    """A horizontal field of view on the ground: apex (x, y) in m, optical-axis yaw and full opening ``fov`` in rad,
    and the range (m) beyond which people are not expected to be detected. Same frame as the tracked positions."""

    x: float
    y: float
    yaw: float
    fov: float
    max_range: float = 8.0

    def __post_init__(self) -> None:
        check_numbers("view", self, ("x", "y", "yaw"))
        check_number("view", "fov", self.fov, low=0, high=2 * math.pi, low_open=True, unit="radians")
        check_number("view", "max_range", self.max_range, low=0, low_open=True, allow_inf=True, unit="metres")

    def contains(self, points: np.ndarray) -> np.ndarray:
        """(N,) bool: which of the (N, 2) points lie inside the cone."""
        d = np.asarray(points, dtype=float).reshape(-1, 2) - (self.x, self.y)
        distance = np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2)
        along = d[:, 0] * math.cos(self.yaw) + d[:, 1] * math.sin(self.yaw)  # cos(off-axis angle) * distance
        return (along >= distance * math.cos(self.fov / 2)) & (distance <= self.max_range)

    def behind(self, points: np.ndarray, occluders: np.ndarray, radius: float) -> np.ndarray:
        """(N,) bool: which of the (N, 2) points the apex sees behind one of the (M, 2) ``occluders``, all of them
        people of ``radius`` (m) seen from above: an occluder nearer by two radii or more (its whole body in front)
        whose outline overlaps the point's (their bearings differ by less than the sum of their angular radii)."""
        p = np.asarray(points, dtype=float).reshape(-1, 2) - (self.x, self.y)
        o = np.asarray(occluders, dtype=float).reshape(-1, 2) - (self.x, self.y)
        p_range, o_range = np.sqrt(p[:, 0] ** 2 + p[:, 1] ** 2), np.sqrt(o[:, 0] ** 2 + o[:, 1] ** 2)
        cross = p[:, None, 0] * o[None, :, 1] - p[:, None, 1] * o[None, :, 0]
        dot = p[:, None, 0] * o[None, :, 0] + p[:, None, 1] * o[None, :, 1]
        apart = np.arctan2(np.abs(cross), dot)  # angle between the two lines of sight
        with np.errstate(divide="ignore"):  # a point at the apex: angular radius pi / 2
            p_half, o_half = (np.arcsin(np.minimum(radius / r, 1.0)) for r in (p_range, o_range))
        overlap = apart < p_half[:, None] + o_half[None, :]
        return np.count_nonzero(overlap & (p_range[:, None] - o_range[None, :] >= 2 * radius), axis=1) > 0


@dataclass(frozen=True, eq=False)
class ViewRegion:
    """An area seen from above, e.g. the ground a fixed camera covers: a simple polygon (K, 2) in m, in the same frame
    as the tracked positions. ``scene_view`` makes one from the positions where people were seen."""

    polygon: np.ndarray
    _shape: Any = field(init=False, repr=False)  # the prepared shapely polygon

    def __post_init__(self) -> None:
        polygon = np.asarray(self.polygon, dtype=float)
        if polygon.ndim != 2 or polygon.shape[1] != 2 or len(polygon) < 3 or not np.isfinite(polygon).all():
            raise InputError(f"view: a region needs 3 or more finite (x, y) corners, got shape {polygon.shape}")
        object.__setattr__(self, "polygon", polygon)
        import shapely.prepared  # here, not at start-up: an import a camera's view cone never needs

        object.__setattr__(self, "_shape", shapely.prepared.prep(shapely.Polygon(polygon)))

    def contains(self, points: np.ndarray) -> np.ndarray:
        """(N,) bool: which of the (N, 2) points lie inside the region (or on its edge)."""
        import shapely

        p = np.asarray(points, dtype=float).reshape(-1, 2)
        return shapely.intersects_xy(self._shape.context, p[:, 0], p[:, 1]).astype(bool)


View = ViewCone | ViewRegion
"""Where the detector looks: a camera's cone or a fixed region."""


def scene_view(positions: np.ndarray, margin: float = 0.0) -> ViewRegion:
    """The convex hull of (N, 2) positions (m) where people were seen, grown by ``margin`` (m)."""
    import shapely

    points = shapely.MultiPoint(np.asarray(positions, dtype=float).reshape(-1, 2))
    hull = points.convex_hull.buffer(margin) if margin > 0 else points.convex_hull
    if not isinstance(hull, shapely.Polygon) or hull.is_empty:
        raise InputError("view: the positions span no area (fewer than three points not on one line)")
    return ViewRegion(np.array(hull.exterior.coords)[:-1])


def camera_fov(calibration: Calibration, mount: CameraMount) -> tuple[float, float]:
    """(yaw of the optical axis, horizontal opening) of the colour camera seen from above, in the mount's ground
    frame (rad): bounded by the image's left and right edges on the principal row."""
    color = calibration.color
    edges = np.array([[-0.5 - color.cx, 0.0, color.fx], [color.width - 0.5 - color.cx, 0.0, color.fx]])
    world = edges @ mount.rotation.T
    left, right = np.arctan2(world[:, 1], world[:, 0]).tolist()
    fov = (left - right) % math.tau  # counter-clockwise from the right edge to the left, across +-pi too
    return math.remainder(right + fov / 2, math.tau), fov


def camera_view_cone(
    calibration: Calibration, mount: CameraMount, pose: RobotPose | None = None, max_range: float = 6.0
) -> ViewCone:
    """The colour camera's field of view on the ground, up to ``max_range`` (m): in the map when the robot's
    ``pose`` is given, else in base_footprint."""
    yaw, fov = camera_fov(calibration, mount)
    x, y = mount.x, mount.y
    if pose is not None:
        (x, y), yaw = pose.to_map(np.array([x, y]))[0].tolist(), pose.yaw_to_map(yaw)
    return ViewCone(x, y, yaw, fov, max_range)


def pipeline_view(frame: Frame, pipeline: Pipeline) -> ViewCone:
    """``camera_view_cone`` of ``frame`` through ``pipeline``: the colour camera's field of view on the ground from the
    frame's robot pose (in the map; without one in base_footprint, the frame of the pipeline's output), up to the
    pipeline's lifting range."""
    return camera_view_cone(frame.calibration, pipeline.mount, frame.robot_pose, pipeline.lift_params.max_range)
