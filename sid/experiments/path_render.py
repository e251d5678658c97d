"""Pictures of plans (OpenCV, BGR uint8): paths drawn over ``costmap.render.render_costmap`` plus a metrics table.

World frame in, pixels out through ``costmap.render.world_to_image``, so paths line up with the costmap, people
and zones drawn there.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from costmap.grid import Costmap2D, GridSpec
from costmap.layered import LayeredCostmap
from costmap.render import Extra, Outline, RobotTask, default_scale, render_costmap, world_to_image
from planner.validity import interpolate
from sid.perception.group import Group

__all__ = [
    "FONT",
    "HALO",
    "PathStyle",
    "ROW_HEIGHT",
    "TEXT",
    "WITHOUT_COLOUR",
    "WITH_COLOUR",
    "add_header",
    "add_table",
    "draw_path",
    "path_extra",
    "render_paths",
]

FONT = cv2.FONT_HERSHEY_SIMPLEX
TEXT = (40, 40, 40)
HALO = (255, 255, 255)
WITH_COLOUR = (170, 20, 150)  # BGR purple: the path with recognition
WITHOUT_COLOUR = (30, 30, 215)  # BGR red: the path without recognition
ROW_HEIGHT = 24


@dataclass(frozen=True)
class PathStyle:
    """How one path is drawn and labelled."""

    label: str
    colour: tuple[int, int, int]
    dashed: bool = False


def _pixels(path: np.ndarray, spec: GridSpec, scale: int) -> np.ndarray:
    return np.rint(world_to_image(path, spec, scale) * 16).astype(np.int32)  # 4 fractional bits (shift=4)


def draw_path(img: np.ndarray, path: np.ndarray, spec: GridSpec, scale: int, style: PathStyle, width: int = 3) -> None:
    """Draw a world-frame path (N, 2) in place, with a white halo so it reads on any cost colour."""
    path = np.asarray(path, dtype=float).reshape(-1, 2)
    if len(path) < 2:
        return
    if style.dashed:
        dash = 0.15  # metres per dash and per gap
        points = interpolate(path, dash / 3)
        run = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])
        on = (run // dash).astype(int) % 2 == 0
        pieces = [points[i : i + 2] for i in range(len(points) - 1) if on[i]]
    else:
        pieces = [path]
    for colour, thickness in ((HALO, width + 3), (style.colour, width)):
        cv2.polylines(img, [_pixels(p, spec, scale) for p in pieces], False, colour, thickness, cv2.LINE_AA, shift=4)


def _legend_swatch(img: np.ndarray, x: int, y: int, style: PathStyle, length: int = 36) -> None:
    if style.dashed:
        for start in range(x, x + length, 12):
            cv2.line(img, (start, y), (start + 6, y), style.colour, 3, cv2.LINE_AA)
    else:
        cv2.line(img, (x, y), (x + length, y), style.colour, 3, cv2.LINE_AA)


def path_extra(path: np.ndarray, style: PathStyle, width: int = 3) -> Extra:
    """A path for ``render_costmap``'s ``extras``: drawn as ``draw_path`` does, listed in the legend by its label."""
    return Extra(
        style.label,
        lambda img, u, v: _legend_swatch(img, u - 11, v, style, 24),
        lambda img, spec, scale: draw_path(img, path, spec, scale, style, width),
    )


def add_table(
    img: np.ndarray, header: Sequence[str], rows: Sequence[tuple[PathStyle | None, Sequence[str]]]
) -> np.ndarray:
    """Append a table under the picture: a header and one row per path (swatch + cells). Returns the new image."""
    columns = [header, *[cells for _, cells in rows]]
    widths = [
        max(cv2.getTextSize(str(col[i]), FONT, 0.45, 1)[0][0] for col in columns) + 18 for i in range(len(header))
    ]
    strip = np.full((ROW_HEIGHT * (len(rows) + 1) + 16, img.shape[1], 3), 255, dtype=np.uint8)
    left = 56 + 48
    for r, (style, cells) in enumerate([(None, header), *rows]):
        y = 18 + r * ROW_HEIGHT
        if style is not None:
            _legend_swatch(strip, 56, y - 5, style)
        x = left
        for i, cell in enumerate(cells):
            cv2.putText(strip, str(cell), (x, y), FONT, 0.45, TEXT, 2 if r == 0 else 1, cv2.LINE_AA)
            x += widths[i]
    cv2.line(strip, (56, 24), (min(x, img.shape[1] - 8), 24), TEXT, 1)
    return np.vstack([img, strip])


def add_header(img: np.ndarray, title: str, subtitle: str = "") -> np.ndarray:
    """Prepend a white strip with a bold title and an optional smaller subtitle. Returns the new image."""
    strip = np.full((64 if subtitle else 40, img.shape[1], 3), 255, dtype=np.uint8)
    cv2.putText(strip, title, (56, 28), FONT, 0.7, TEXT, 2, cv2.LINE_AA)
    if subtitle:
        cv2.putText(strip, subtitle, (56, 52), FONT, 0.45, TEXT, 1, cv2.LINE_AA)
    return np.vstack([strip, img])


def render_paths(
    layered: LayeredCostmap | Costmap2D,
    paths: Sequence[tuple[np.ndarray, PathStyle]],
    *,
    robot: RobotTask | None = None,
    groups: Sequence[Group] | None = None,
    title: str | None = None,
    scale: int | None = None,
    outlines: Sequence[Outline] = (),
) -> tuple[np.ndarray, int]:
    """The costmap picture of ``layered`` (a ``LayeredCostmap`` or ``Costmap2D``) with paths on top; (image, scale).

    ``outlines``: shapes of the known map to draw whole (``costmap.render.render_costmap``)."""
    spec = layered.spec
    scale = default_scale(spec) if scale is None else scale
    extras = [path_extra(path, style) for path, style in paths]
    img = render_costmap(
        layered, groups=groups, robot=robot, title=title, scale=scale, outlines=outlines, extras=extras
    )
    return img, scale
