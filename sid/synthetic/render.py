"""Exact depth, label and shading images of capsule bodies in front of a ground plane and a back wall.

A vectorised numpy ray caster: every shape is intersected analytically with the rays of the pixels inside its
projected bounding box, and a z-buffer keeps the nearest hit. Rays are built as ``K^-1 [u, v, 1]``, so the ray
parameter of a hit *is* its depth z in the camera's optical frame (x right, y down, z forward, metres), which is
what a RealSense depth image stores. Pixel centres follow ``sid.perception.camera``: (0, 0) is the centre of the
top-left pixel.

Why not a library renderer: OpenGL/pyrender/Open3D would add heavy dependencies (and a display or EGL context)
to draw a few dozen quadrics; the analytic intersection is exact, short and fast enough (docs/parameters.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sid.checks import check_number
from sid.errors import InputError
from sid.perception.camera import Extrinsics, Intrinsics, pixel_rays

__all__ = ["Background", "Capsule", "LABEL_GROUND", "LABEL_NONE", "LABEL_WALL", "RayCaster", "Rendering"]

# Label image values that are not a body index.
LABEL_NONE = -1  # nothing hit (sky / beyond every surface)
LABEL_GROUND = -2
LABEL_WALL = -3

_NEAR = 1e-3  # m: hits closer than this to the optical centre are ignored


@dataclass(frozen=True)
class Capsule:
    """A capsule stretched along its own axes (covers spheres, ellipsoids, limbs and an elliptic torso).

    The solid is ``{centre + axes @ q : dist(q, S) <= 1}`` where S is the segment from (0, 0, -half_length) to
    (0, 0, +half_length) in the shape's unit space. ``axes`` (3, 3): its columns are the shape's local x, y, z
    directions scaled by the semi-axes (metres), so a round limb of radius r has ``axes = r * R``. ``half_length``
    is dimensionless (unit-space); 0 gives an ellipsoid.
    """

    centre: np.ndarray
    axes: np.ndarray
    half_length: float = 0.0

    def __post_init__(self) -> None:
        centre = np.asarray(self.centre, dtype=float).reshape(3)
        axes = np.asarray(self.axes, dtype=float).reshape(3, 3)
        if not (np.all(np.isfinite(centre)) and np.all(np.isfinite(axes)) and np.isfinite(self.half_length)):
            raise InputError("capsule: centre, axes and half_length must be finite")
        if abs(np.linalg.det(axes)) < 1e-12:
            raise InputError("capsule: axes are degenerate (zero semi-axis)")
        if self.half_length < 0:
            raise InputError(f"capsule: half_length must be >= 0, got {self.half_length}")
        object.__setattr__(self, "centre", centre)
        object.__setattr__(self, "axes", axes)

    @classmethod
    def segment(cls, a: np.ndarray, b: np.ndarray, radius: float) -> Capsule:
        """A round capsule of ``radius`` (m) around the segment from ``a`` to ``b`` (metres)."""
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        axis = b - a
        length = float(np.linalg.norm(axis))
        z = axis / length if length > 1e-9 else np.array([0.0, 0.0, 1.0])
        x, y = _perpendicular_basis(z)
        return cls((a + b) / 2, radius * np.stack([x, y, z], axis=1), length / (2 * radius))

    @classmethod
    def oriented(
        cls, centre: np.ndarray, rotation: np.ndarray, semi_axes: tuple[float, float, float], length: float = 0.0
    ) -> Capsule:
        """An elliptic capsule: cross-section semi-axes ``semi_axes[:2]`` (m) along the columns 0 and 1 of
        ``rotation``, a straight part ``length`` (m) along column 2, capped by half-ellipsoids of semi-axis
        ``semi_axes[2]`` (m). ``length = 0`` gives an ellipsoid."""
        rotation = np.asarray(rotation, dtype=float).reshape(3, 3)
        return cls(centre, rotation * np.asarray(semi_axes, dtype=float), length / (2 * semi_axes[2]))

    def transformed(self, transform: Extrinsics) -> Capsule:
        """The same solid with its coordinates mapped by ``transform`` (e.g. world -> camera)."""
        return Capsule(transform.apply(self.centre[None])[0], transform.rotation @ self.axes, self.half_length)

    def box_corners(self) -> np.ndarray:
        """(8, 3) corners of a box that contains the solid (same frame as ``centre``)."""
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
        signs[:, 2] *= self.half_length + 1.0
        return self.centre + signs @ self.axes.T


def _perpendicular_basis(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors that complete the unit vector z to a right-handed orthonormal basis."""
    # helper x z with helper = e_x (or e_y when z is close to e_x), written out: np.cross is slow on 3-vectors.
    x = np.array([0.0, -z[2], z[1]]) if abs(z[0]) < 0.9 else np.array([z[2], 0.0, -z[0]])
    x /= np.sqrt(x @ x)
    y = np.array([z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]])
    return x, y


@dataclass(frozen=True)
class Background:
    """Static scene around the people, in the world frame: the ground plane z = 0 (if ``ground``) and a wall
    perpendicular to the world x axis at ``wall_distance`` metres (None: no wall)."""

    ground: bool = True
    wall_distance: float | None = 5.0

    def __post_init__(self) -> None:
        if self.wall_distance is not None:
            check_number("background", "wall_distance", self.wall_distance, low=0, low_open=True, unit="metres")


@dataclass
class Rendering:
    """Images from one camera: ``depth`` (H, W) float32 z in metres (0 = nothing hit); ``label`` (H, W) int16:
    body index, or LABEL_NONE / LABEL_GROUND / LABEL_WALL; ``shade`` (H, W) float32 in [0, 1], cosine between
    surface normal and viewing ray (only when shading was asked for, else None)."""

    depth: np.ndarray
    label: np.ndarray
    shade: np.ndarray | None


class RayCaster:
    """Renders bodies (lists of world-frame capsules) as seen by one pinhole camera.

    ``world_to_camera`` maps world-frame points into this camera's optical frame. The background (ground, wall)
    is rendered once at construction and copied into every frame.
    """

    def __init__(self, intrinsics: Intrinsics, world_to_camera: Extrinsics, background: Background | None = None):
        self.intrinsics = intrinsics
        self.world_to_camera = world_to_camera
        self.background = background or Background()
        # (W,) x/z of each column and (H,) y/z of each row
        self._ray_x, self._ray_y = pixel_rays(np.arange(intrinsics.width), np.arange(intrinsics.height), intrinsics)
        self._bg_depth, self._bg_label, self._bg_shade, self._bg_world = self._render_background()

    def _render_background(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        shape = (self.intrinsics.height, self.intrinsics.width)
        depth = np.full(shape, np.inf)
        label = np.full(shape, LABEL_NONE, dtype=np.int16)
        shade = np.zeros(shape)
        rays = np.stack(np.broadcast_arrays(self._ray_x[None, :], self._ray_y[:, None], 1.0), axis=-1)  # (H, W, 3)
        ray_norm = np.sqrt(self._ray_x[None, :] ** 2 + self._ray_y[:, None] ** 2 + 1.0)
        rotation, translation = self.world_to_camera.rotation, self.world_to_camera.translation
        planes = []  # (world normal facing the camera side, world point, label)
        if self.background.ground:
            planes.append((np.array([0.0, 0.0, 1.0]), np.zeros(3), LABEL_GROUND))
        if self.background.wall_distance is not None:
            planes.append((np.array([-1.0, 0.0, 0.0]), np.array([self.background.wall_distance, 0.0, 0.0]), LABEL_WALL))
        for normal_w, point_w, plane_label in planes:
            normal_c = rotation @ normal_w
            offset = normal_c @ (rotation @ point_w + translation)  # plane: normal_c . p = offset
            denom = rays @ normal_c
            with np.errstate(divide="ignore", invalid="ignore"):
                t = np.where(denom < 0, offset / denom, np.inf)  # only rays that see the plane's front side
            t[t <= _NEAR] = np.inf
            closer = t < depth
            depth[closer] = t[closer]
            label[closer] = plane_label
            shade[closer] = -denom[closer] / ray_norm[closer]
        hit = np.isfinite(depth)
        depth[~hit] = 0.0
        points_c = rays * depth[..., None]
        world = (points_c - translation) @ rotation  # camera -> world, rows
        world[~hit] = np.nan
        return depth.astype(np.float32), label, shade.astype(np.float32), world.astype(np.float32)

    @property
    def background_world(self) -> np.ndarray:
        """(H, W, 3) world-frame point seen at each pixel of the background (NaN where nothing is hit)."""
        return self._bg_world

    def render(
        self,
        bodies: Sequence[Sequence[Capsule]],
        shading: bool = False,
        labels: Sequence[int] | None = None,
        base: Rendering | None = None,
    ) -> Rendering:
        """Depth, labels and optionally shading of world-frame bodies.

        labels: each body's label (default: its position in ``bodies``). base: a rendering of other bodies by this
        caster (made with the same ``shading``) to draw these over instead of the empty background, so bodies that
        do not move are cast once.
        """
        if base is not None and shading and base.shade is None:
            raise InputError("render: shading over a base rendering needs a base made with shading=True")
        depth = (self._bg_depth if base is None else base.depth).copy()
        depth[depth == 0] = np.inf
        label = (self._bg_label if base is None else base.label).copy()
        labels = range(len(bodies)) if labels is None else labels
        if len(labels) != len(bodies):
            raise InputError(f"render: {len(labels)} labels for {len(bodies)} bodies")
        shapes = [
            (index, shape.transformed(self.world_to_camera))
            for index, body in zip(labels, bodies, strict=True)
            for shape in body
        ]
        windows = [self._pixel_box(shape) for _, shape in shapes]
        # Which shape is nearest at each pixel (-1: background); only needed to shade the visible surfaces.
        nearest = np.full(depth.shape, -1, dtype=np.int32) if shading else None
        for number, ((index, shape), window) in enumerate(zip(shapes, windows, strict=True)):
            if window is not None:
                self._cast(shape, window, depth, label, index, nearest, number)
        depth[np.isinf(depth)] = 0.0
        shade = None
        if shading:
            shade = (self._bg_shade if base is None or base.shade is None else base.shade).copy()
            assert nearest is not None  # made when shading
            for number, ((_, shape), window) in enumerate(zip(shapes, windows, strict=True)):
                if window is not None:
                    self._shade(shape, window, depth, nearest, number, shade)
        return Rendering(depth, label, shade)

    def _pixel_box(self, shape: Capsule) -> tuple[int, int, int, int] | None:
        """Inclusive-exclusive pixel window (u0, u1, v0, v1) that contains the shape's image, None if unseen."""
        corners = shape.box_corners()
        z = corners[:, 2]
        if np.all(z <= _NEAR):
            return None
        intr = self.intrinsics
        if np.any(z <= _NEAR):  # the box straddles the camera plane: its image is unbounded
            return 0, intr.width, 0, intr.height
        u = corners[:, 0] / z * intr.fx + intr.cx
        v = corners[:, 1] / z * intr.fy + intr.cy
        u0, u1 = max(int(np.floor(u.min())), 0), min(int(np.ceil(u.max())) + 1, intr.width)
        v0, v1 = max(int(np.floor(v.min())), 0), min(int(np.ceil(v.max())) + 1, intr.height)
        if u0 >= u1 or v0 >= v1:
            return None
        return u0, u1, v0, v1

    def _unit_rays(self, shape: Capsule, window: tuple[int, int, int, int]) -> tuple[np.ndarray, ...]:
        """Ray origin (3,) and the three (h, w) direction components of the window's rays in the shape's unit
        space, plus the camera-to-unit-space matrix."""
        u0, u1, v0, v1 = window
        inverse = np.linalg.inv(shape.axes)  # camera -> unit space (linear part)
        origin = -inverse @ shape.centre  # the optical centre in unit space
        rx, ry = self._ray_x[None, u0:u1], self._ray_y[v0:v1, None]
        d0 = inverse[0, 0] * rx + inverse[0, 1] * ry + inverse[0, 2]
        d1 = inverse[1, 0] * rx + inverse[1, 1] * ry + inverse[1, 2]
        d2 = inverse[2, 0] * rx + inverse[2, 1] * ry + inverse[2, 2]
        return inverse, origin, d0, d1, d2

    def _cast(
        self,
        shape: Capsule,
        window: tuple[int, int, int, int],
        depth: np.ndarray,
        label: np.ndarray,
        index: int,
        nearest: np.ndarray | None,
        number: int,
    ) -> None:
        """Intersect one camera-frame shape with its window's rays and update the buffers in place."""
        _, origin, d0, d1, d2 = self._unit_rays(shape, window)
        hl = shape.half_length
        with np.errstate(divide="ignore", invalid="ignore"):
            # Side of the unit cylinder x^2 + y^2 = 1, |z| <= hl (ray parameter t = depth z, NaN = miss).
            a = d0 * d0 + d1 * d1
            b = origin[0] * d0 + origin[1] * d1
            c = origin[0] ** 2 + origin[1] ** 2 - 1.0
            t = (-b - np.sqrt(b * b - a * c)) / a
            t[~(np.abs(origin[2] + t * d2) <= hl)] = np.inf  # misses and hits beyond the ends
            # End spheres of radius 1 at z = -hl and z = +hl (one sphere when hl = 0).
            dd = a + d2 * d2
            for end in (-hl, hl) if hl > 0 else (0.0,):
                oz = origin[2] - end
                b2 = b + oz * d2
                t_end = (-b2 - np.sqrt(b2 * b2 - dd * (c + oz * oz))) / dd
                np.fmin(t, t_end, out=t)  # fmin ignores the NaN of a miss
        t[t <= _NEAR] = np.inf
        u0, u1, v0, v1 = window
        depth_view = depth[v0:v1, u0:u1]
        closer = t < depth_view
        depth_view[closer] = t[closer]
        label[v0:v1, u0:u1][closer] = index
        if nearest is not None:
            nearest[v0:v1, u0:u1][closer] = number

    def _shade(
        self,
        shape: Capsule,
        window: tuple[int, int, int, int],
        depth: np.ndarray,
        nearest: np.ndarray,
        number: int,
        shade: np.ndarray,
    ) -> None:
        """Cosine between the surface normal and the viewing ray on the pixels where shape ``number`` is nearest."""
        u0, u1, v0, v1 = window
        rows, cols = np.nonzero(nearest[v0:v1, u0:u1] == number)
        if len(rows) == 0:
            return
        rows += v0
        cols += u0
        ray = np.column_stack([self._ray_x[cols], self._ray_y[rows], np.ones(len(rows))])
        inverse = np.linalg.inv(shape.axes)
        q = (ray * depth[rows, cols][:, None] - shape.centre) @ inverse.T  # unit-space hit points
        q[:, 2] -= np.clip(q[:, 2], -shape.half_length, shape.half_length)  # unit-space normal
        normal = q @ inverse  # camera-frame normal (inverse^T n, as rows)
        cosine = -np.einsum("ij,ij->i", normal, ray) / np.sqrt(
            np.einsum("ij,ij->i", normal, normal) * np.einsum("ij,ij->i", ray, ray)
        )
        shade[rows, cols] = np.clip(cosine, 0.0, 1.0)
