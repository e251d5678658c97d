"""Pictures of costmaps (OpenCV, BGR uint8): costs, known obstacles' outlines, people with facing arrows coloured by
group, each group's o-space as its record holds it (a polygon, a segment or a point) and its interaction zone, a colour
scale and a legend of exactly what is drawn.

Image layout: world x to the right, world y up; the map sits at (MARGIN_LEFT, MARGIN_TOP) with ``scale`` pixels
per cell, axes in metres below and left of it, the colour scale and a legend of what is drawn to its right. People's
id labels are placed last, clear of each other and of everything drawn on the map.
``world_to_image`` maps world points to pixel coordinates of that layout so other modules (the planner) can draw on
top.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

import cv2
import numpy as np
import shapely
from numpy.typing import ArrayLike

from costmap.grid import INSCRIBED, LETHAL, MAX_NON_OBSTACLE, NO_INFORMATION, Costmap2D, GridSpec
from costmap.layered import LayeredCostmap
from costmap.layers.obstacle import SCAN as SCAN_INPUT  # SCAN is the scan's colour here
from costmap.layers.social import GROUPS, PEOPLE, SocialLayer, SocialParams, group_zone_polygon
from costmap.scan import LaserScan
from sid.errors import InputError
from sid.labels import place_labels
from sid.perception.group import Group
from sid.perception.people import Person

__all__ = [
    "CAMERA",
    "COST_COLOURS",
    "CameraView",
    "Extra",
    "FONT",
    "GOAL",
    "GROUP_COLOURS",
    "INSCRIBED_COLOUR",
    "LEGEND",
    "OBSTACLE",
    "Outline",
    "PERSON",
    "RobotTask",
    "SCAN",
    "START",
    "Swatch",
    "TEXT",
    "UNKNOWN_COLOUR",
    "TICK_MIN_PX",
    "ZONE",
    "axis_ticks",
    "dashed_polyline",
    "default_scale",
    "person_colours",
    "person_swatch",
    "render_costmap",
    "world_to_image",
]

MARGIN_LEFT, MARGIN_TOP, MARGIN_BOTTOM, PANEL_WIDTH, PANEL_HEIGHT = 56, 40, 44, 190, 450


class RobotTask(Protocol):
    """What a picture shows of a robot's task: start and goal poses (x, y, yaw; world frame) and disc radius (m)."""

    @property
    def start(self) -> tuple[float, float, float]: ...
    @property
    def goal(self) -> tuple[float, float, float]: ...
    @property
    def radius(self) -> float: ...


Outline = tuple[ArrayLike, bool]
"""A shape drawn over the map: its world points (N, 2) (metres) and whether the polyline closes into a polygon."""


@dataclass(frozen=True)
class CameraView:
    """A camera seen from above (world frame): position (m), yaw of its optical axis and horizontal field of view
    (rad)."""

    x: float
    y: float
    yaw: float
    fov: float


FONT = cv2.FONT_HERSHEY_SIMPLEX
TEXT = (40, 40, 40)
PERSON = (200, 110, 20)  # BGR: blue, a person in no group
# BGR, one per group in the order given (then again): green, crimson, violet, olive, dark cyan, brown; clear of the
# yellow-to-brown costs, the blue of people alone and the paths' purple and red.
GROUP_COLOURS = ((40, 150, 20), (120, 30, 210), (190, 60, 100), (0, 120, 120), (140, 120, 0), (20, 70, 140))
ZONE = GROUP_COLOURS[0]
START = (90, 40, 0)  # BGR: navy, the robot
GOAL = (30, 30, 220)  # red
SCAN = (0, 0, 255)  # pure red dots with a black rim: clear on black walls, steel blue, the costs and white
CAMERA = (90, 60, 60)  # dark slate
OBSTACLE = (150, 150, 0)  # teal: the outlines of known obstacles, clear on black lethal cells and on steel blue
INSCRIBED_COLOUR = (200, 140, 110)  # RGB (110, 140, 200), steel blue
UNKNOWN_COLOUR = (205, 205, 205)  # map_saver's unknown grey
# Graded costs 1..252: ColorBrewer YlOrBr anchors (RGB), light to dark, clear of black walls and grey unknown.
_ANCHORS = np.array([[1, 255, 247, 188], [80, 254, 196, 79], [160, 236, 112, 20], [252, 140, 45, 4]], dtype=float)


def _cost_lut() -> np.ndarray:
    lut = np.zeros((256, 3), dtype=np.uint8)
    lut[0] = (255, 255, 255)
    graded = np.arange(1, MAX_NON_OBSTACLE + 1)
    for channel in range(3):  # RGB anchors -> BGR table
        lut[1 : MAX_NON_OBSTACLE + 1, 2 - channel] = np.interp(graded, _ANCHORS[:, 0], _ANCHORS[:, 1 + channel])
    lut[INSCRIBED], lut[LETHAL], lut[NO_INFORMATION] = INSCRIBED_COLOUR, (0, 0, 0), UNKNOWN_COLOUR
    return lut


COST_COLOURS = _cost_lut()


def default_scale(spec: GridSpec, target_width: int = 800) -> int:
    """Pixels per cell for a map about ``target_width`` pixels wide (at least 1)."""
    return max(1, round(target_width / spec.width))


def world_to_image(xy: ArrayLike, spec: GridSpec, scale: int) -> np.ndarray:
    """World points (N, 2) -> pixel coordinates (N, 2) as (u right, v down), float, in ``render_costmap``'s layout."""
    m = spec.world_to_map(xy)
    return np.stack([MARGIN_LEFT + m[:, 0] * scale, MARGIN_TOP + (spec.height - m[:, 1]) * scale], axis=1)


def _px(points: ArrayLike, spec: GridSpec, scale: int) -> np.ndarray:
    """Integer pixel coordinates with 4 fractional bits, for OpenCV's ``shift=4`` drawing."""
    return np.rint(world_to_image(points, spec, scale) * 16).astype(np.int32)


def _text(
    img: np.ndarray,
    text: str,
    org: tuple[int, int],
    size: float = 0.45,
    colour: tuple[int, int, int] = TEXT,
    thick: int = 1,
) -> None:
    cv2.putText(img, text, org, FONT, size, colour, thick, cv2.LINE_AA)


TICK_MIN_PX = 30
"""Axis ticks are at least this many pixels apart, so that labels such as "-100" do not touch."""
_TICK_STEPS = [k * 10.0**e for e in range(-2, 5) for k in (1.0, 2.0, 5.0)]  # metres, the 1-2-5 series


def _multiples(lo: float, hi: float, step: float) -> list[float]:
    """The multiples of ``step`` in [lo, hi] (metres, a nanometre of slack at both ends), 0 never signed."""
    first, last = math.ceil(lo / step - 1e-9), math.floor(hi / step + 1e-9)
    return [round(k * step, 9) + 0.0 for k in range(first, last + 1)]  # + 0.0: -0.0 becomes 0.0


def axis_ticks(spec: GridSpec, scale: int) -> tuple[list[float], list[float]]:
    """World x and y (m) of the picture's axis ticks at ``scale`` pixels per cell: the multiples of one step of the
    1-2-5 series, 1 m unless ticks a metre apart would be closer than ``TICK_MIN_PX`` (a larger step: a large map)
    or a side of the map would hold fewer than three (a smaller one, still ``TICK_MIN_PX`` apart: a map a metre
    across)."""
    x0, y0, x1, y1 = spec.bounds
    px_per_m = scale / spec.resolution
    i = _TICK_STEPS.index(1.0)
    while _TICK_STEPS[i] * px_per_m < TICK_MIN_PX and i + 1 < len(_TICK_STEPS):
        i += 1
    while (
        i > 0
        and _TICK_STEPS[i - 1] * px_per_m >= TICK_MIN_PX
        and min(len(_multiples(x0, x1, _TICK_STEPS[i])), len(_multiples(y0, y1, _TICK_STEPS[i]))) < 3
    ):
        i -= 1
    step = _TICK_STEPS[i]
    return _multiples(x0, x1, step), _multiples(y0, y1, step)


def _axes(img: np.ndarray, spec: GridSpec, scale: int) -> None:
    x0, y0, _, _ = spec.bounds
    xs, ys = axis_ticks(spec, scale)
    h_px = spec.height * scale
    for x in xs:
        u = int(world_to_image([[x, y0]], spec, scale)[0, 0])
        cv2.line(img, (u, MARGIN_TOP + h_px), (u, MARGIN_TOP + h_px + 5), TEXT, 1)
        _text(img, f"{x:g}", (u - 8, MARGIN_TOP + h_px + 20), 0.4)
    for y in ys:
        v = int(world_to_image([[x0, y]], spec, scale)[0, 1])
        cv2.line(img, (MARGIN_LEFT - 5, v), (MARGIN_LEFT, v), TEXT, 1)
        _text(img, f"{y:g}", (MARGIN_LEFT - 34, v + 5), 0.4)
    _text(img, "x (m)", (MARGIN_LEFT + spec.width * scale // 2 - 20, MARGIN_TOP + h_px + 38), 0.45)
    _text(img, "y (m)", (4, MARGIN_TOP - 8), 0.45)


Swatch = Callable[[np.ndarray, int, int], object]
"""Draws a legend entry's symbol centred at pixel (u, v) of an image (in place; what it returns is ignored)."""


@dataclass(frozen=True)
class Extra:
    """Something a caller draws on the map and its legend entry: ``draw(img, spec, scale)`` draws in place in
    ``render_costmap``'s layout (world points through ``world_to_image``), ``swatch`` is the legend's symbol."""

    label: str
    swatch: Swatch
    draw: Callable[[np.ndarray, GridSpec, int], None]


def person_swatch(colour: tuple[int, int, int], arrow: bool = True) -> Swatch:
    """The legend's symbol of a person drawn in ``colour`` (BGR): a dot, with a facing arrow unless ``arrow`` is
    False."""

    def swatch(img: np.ndarray, u: int, v: int) -> None:
        cv2.circle(img, (u - 4, v), 6, colour, -1, cv2.LINE_AA)
        if arrow:
            cv2.arrowedLine(img, (u - 4, v), (u + 12, v), colour, 2, cv2.LINE_AA, tipLength=0.4)

    return swatch


def _group_swatch(colour: tuple[int, int, int]) -> Swatch:
    def swatch(img: np.ndarray, u: int, v: int) -> None:
        for du in (-6, 6):
            cv2.circle(img, (u + du, v), 5, colour, -1, cv2.LINE_AA)

    return swatch


def _legend_camera(img: np.ndarray, u: int, v: int) -> None:
    cv2.line(img, (u - 6, v), (u + 16, v - 8), CAMERA, 1, cv2.LINE_AA)
    cv2.line(img, (u - 6, v), (u + 16, v + 8), CAMERA, 1, cv2.LINE_AA)
    _camera_glyph(img, np.array([u - 6, v]), 0.0)


def _scan_dot(img: np.ndarray, u: int, v: int) -> None:
    cv2.circle(img, (u, v), 3, (0, 0, 0), -1)
    cv2.circle(img, (u, v), 2, SCAN, -1)


LEGEND: dict[str, Swatch] = {  # the fixed entries, name -> swatch
    "unknown facing: id?": lambda img, u, v: _text(img, "3?", (u - 8, v + 5), 0.45, PERSON, 1),
    "o-space (the group's zone)": lambda img, u, v: cv2.rectangle(img, (u - 8, v - 5), (u + 8, v + 5), TEXT, 1),
    "o-space: one point, or under 10 px": lambda img, u, v: cv2.circle(img, (u, v), 4, TEXT, 1, cv2.LINE_AA),
    "interest point": lambda img, u, v: cv2.drawMarker(img, (u, v), TEXT, cv2.MARKER_CROSS, 10, 2, cv2.LINE_AA),
    "interaction zone (costmap)": lambda img, u, v: cv2.rectangle(img, (u - 9, v - 6), (u + 9, v + 6), TEXT, 2),
    "known obstacle": lambda img, u, v: cv2.rectangle(img, (u - 9, v - 6), (u + 9, v + 6), OBSTACLE, 2),
    "LiDAR hits": _scan_dot,
    "robot start": lambda img, u, v: cv2.circle(img, (u, v), 6, START, 2, cv2.LINE_AA),
    "goal": lambda img, u, v: cv2.drawMarker(img, (u, v), GOAL, cv2.MARKER_TILTED_CROSS, 12, 2, cv2.LINE_AA),
    "camera, field of view": _legend_camera,
}
LEGEND_ROW, MAX_GROUP_ENTRIES = 22, 6
# The panel right of the map (px): its gap from the map, the top and right padding, the swatches' width, a legend
# label's offset from the panel's left, the graded colour scale's height and the space below it (or the first row's
# baseline without a scale), and the space between the special values and the legend.
PANEL_GAP, PANEL_PAD, SWATCH_WIDTH, LABEL_X = 22, 10, 22, 34
SCALE_HEIGHT, SCALE_GAP, NO_SCALE = 200, 24, 14
_SPECIALS_GAP = 8
_SPECIALS = ((INSCRIBED, "253 inscribed"), (LETHAL, "254 lethal"), (NO_INFORMATION, "255 unknown"))


def _members(group: Group) -> str:
    """The legend's name of a group: its members' ids, or, when they do not fit, how many (with "people", so that
    "group of 6" is never read as the group of person 6)."""
    ids = ", ".join(str(m) for m in group.members)
    return f"group of {ids}" if len(ids) <= 18 else f"group of {len(group.members)} people"


def _legend_rows(
    people: Sequence[Person],
    groups: Sequence[Group],
    drawn: dict[str, bool],
    extras: Sequence[Extra],
    people_rows: bool = True,
) -> list[tuple[str, Swatch]]:
    """The legend, in order: people alone (unless not ``people_rows``: the caller coloured the people), one row per
    group in its colour, then each fixed entry drawn, then the callers' ``extras``."""
    grouped = {m for g in groups for m in g.members}
    alone = [p for p in people if p.id not in grouped] if people_rows else []
    rows: list[tuple[str, Swatch]] = []
    if any(p.theta is not None for p in alone):
        rows.append(("person in no group, facing", person_swatch(PERSON)))
    elif alone:  # drawn without an arrow: their facings are unknown ("unknown facing: id?")
        rows.append(("person in no group", person_swatch(PERSON, arrow=False)))
    for i, group in enumerate(groups[:MAX_GROUP_ENTRIES]):
        rows.append((_members(group), _group_swatch(GROUP_COLOURS[i % len(GROUP_COLOURS)])))
    if len(groups) > MAX_GROUP_ENTRIES:
        rows.append((f"{len(groups) - MAX_GROUP_ENTRIES} more groups", lambda img, u, v: None))
    rows += [(name, LEGEND[name]) for name in LEGEND if drawn.get(name)]
    return rows + [(extra.label, extra.swatch) for extra in extras]


def _panel_contents(costs: np.ndarray) -> tuple[bool, list[tuple[int, str]]]:
    """What the panel shows of ``costs``: whether any cost is graded (the colour scale), and the special values
    present with their labels."""
    graded = bool(np.any((costs > 0) & (costs <= MAX_NON_OBSTACLE)))
    return graded, [(value, label) for value, label in _SPECIALS if np.any(costs == value)]


def _panel_size(costs: np.ndarray, rows: Sequence[tuple[str, Swatch]]) -> tuple[int, int]:
    """Width and height (px) of ``_panel`` for these costs and legend rows."""
    graded, specials = _panel_contents(costs)
    height = PANEL_PAD + (SCALE_HEIGHT + SCALE_GAP if graded else NO_SCALE)
    height += LEGEND_ROW * len(specials) + _SPECIALS_GAP + LEGEND_ROW * len(rows)
    widths = [cv2.getTextSize(name, FONT, 0.4, 1)[0][0] for name, _ in rows]
    return max(PANEL_WIDTH, PANEL_GAP + LABEL_X + max(widths, default=0) + PANEL_PAD), height


def _panel(img: np.ndarray, spec: GridSpec, scale: int, costs: np.ndarray, rows: Sequence[tuple[str, Swatch]]) -> None:
    """Right of the map: the colour scale if any cost is graded, the special values present, then the legend."""
    left, y = MARGIN_LEFT + spec.width * scale + PANEL_GAP, MARGIN_TOP + PANEL_PAD
    width = SWATCH_WIDTH
    graded, specials = _panel_contents(costs)
    if graded:
        values = np.linspace(MAX_NON_OBSTACLE, 0, SCALE_HEIGHT).round().astype(np.uint8)
        img[y : y + SCALE_HEIGHT, left : left + width] = COST_COLOURS[values][:, None, :]
        cv2.rectangle(img, (left, y), (left + width, y + SCALE_HEIGHT), TEXT, 1)
        _text(img, "cost", (left, y - 6), 0.45)
        for value in (0, 50, 100, 150, 200, 252):
            v = y + int(round((MAX_NON_OBSTACLE - value) / MAX_NON_OBSTACLE * (SCALE_HEIGHT - 1)))
            cv2.line(img, (left + width, v), (left + width + 4, v), TEXT, 1)
            _text(img, str(value), (left + width + 7, v + 4), 0.4)
        y += SCALE_HEIGHT + SCALE_GAP
    else:
        y += NO_SCALE
    for value, label in specials:
        cv2.rectangle(img, (left, y - 11), (left + width, y + 3), tuple(int(c) for c in COST_COLOURS[value]), -1)
        cv2.rectangle(img, (left, y - 11), (left + width, y + 3), TEXT, 1)
        _text(img, label, (left + width + 7, y), 0.4)
        y += LEGEND_ROW
    y += _SPECIALS_GAP
    for name, swatch in rows:
        swatch(img, left + SWATCH_WIDTH // 2, y - 4)  # centred over the swatches above
        _text(img, name, (left + LABEL_X, y), 0.4)
        y += LEGEND_ROW


def _camera_glyph(img: np.ndarray, apex: np.ndarray, yaw: float) -> None:
    """A small filled wedge (16 px) with its apex at pixel ``apex``, opening along world ``yaw``."""
    forward, side = np.array([np.cos(yaw), -np.sin(yaw)]), np.array([np.sin(yaw), np.cos(yaw)])
    corners = [apex, apex + 16 * forward + 7 * side, apex + 16 * forward - 7 * side]
    cv2.fillConvexPoly(img, np.rint(np.array(corners) * 16).astype(np.int32), CAMERA, cv2.LINE_AA, shift=4)


def _draw_camera(img: np.ndarray, spec: GridSpec, scale: int, camera: CameraView) -> None:
    """The field of view, shaded and edged up to the map's border, and the camera on top of it."""
    x0, y0, x1, y1 = spec.bounds
    reach = float(np.hypot(x1 - x0, y1 - y0))
    angles = np.linspace(camera.yaw + camera.fov / 2, camera.yaw - camera.fov / 2, 16)
    origin = np.array([camera.x, camera.y])
    wedge = [origin] + [origin + reach * np.array([np.cos(a), np.sin(a)]) for a in angles]
    rows, cols = (
        slice(MARGIN_TOP, MARGIN_TOP + spec.height * scale),
        slice(MARGIN_LEFT, MARGIN_LEFT + spec.width * scale),
    )
    shaded = img.copy()
    cv2.fillPoly(shaded, [_px(np.array(wedge), spec, scale)], CAMERA, cv2.LINE_AA, shift=4)
    img[rows, cols] = cv2.addWeighted(img[rows, cols], 0.9, shaded[rows, cols], 0.1, 0)
    for end in (wedge[1], wedge[-1]):
        (u0, v0), (u1, v1) = world_to_image(np.array([origin, end]), spec, scale).astype(int)
        box = (MARGIN_LEFT, MARGIN_TOP, spec.width * scale, spec.height * scale)
        inside, a, b = cv2.clipLine(box, (u0, v0), (u1, v1))
        if inside:
            cv2.line(img, a, b, CAMERA, 1, cv2.LINE_AA)
    _camera_glyph(img, world_to_image(origin[None], spec, scale)[0], camera.yaw)


def _draw_outlines(img: np.ndarray, spec: GridSpec, scale: int, outlines: Sequence[Outline]) -> None:
    for points, closed in outlines:
        ring = _px(np.asarray(points, dtype=float).reshape(-1, 2), spec, scale)
        cv2.polylines(img, [ring], bool(closed), OBSTACLE, 2, cv2.LINE_AA, shift=4)


def dashed_polyline(
    img: np.ndarray, points: ArrayLike, closed: bool, colour: tuple[int, int, int], thickness: int = 2, dash: int = 9
) -> None:
    """A dashed polyline through the pixel points (N, 2) (u, v; floats), drawn in place: dashes and gaps of ``dash``
    px along the line, continued from one segment to the next; closed back to the first point when ``closed``."""
    path = np.asarray(points, dtype=float).reshape(-1, 2)
    if closed and len(path) > 1:
        path = np.vstack([path, path[:1]])
    steps = np.hypot(*np.diff(path, axis=0).T)
    along = np.concatenate([[0.0], np.cumsum(steps)])
    for start in np.arange(0.0, along[-1], 2 * dash):
        stop = min(start + dash, along[-1])
        ends = np.stack([np.interp([start, stop], along, path[:, k]) for k in (0, 1)], axis=1)
        inner = path[(along > start) & (along < stop)]  # the corners a dash turns round
        piece = np.vstack([ends[:1], inner, ends[1:]])
        cv2.polylines(img, [np.rint(piece * 16).astype(np.int32)], False, colour, thickness, cv2.LINE_AA, shift=4)


def person_colours(people: Sequence[Person], groups: Sequence[Group]) -> dict[int, tuple[int, int, int]]:
    """Each person's colour (BGR) by id: their group's (``GROUP_COLOURS`` in the order of ``groups``), or ``PERSON``."""
    colours = {p.id: PERSON for p in people}
    for i, group in enumerate(groups):
        colours.update(dict.fromkeys(group.members, GROUP_COLOURS[i % len(GROUP_COLOURS)]))
    return colours


def _draw_people(
    img: np.ndarray, spec: GridSpec, scale: int, people: Sequence[Person], colours: dict[int, tuple[int, int, int]],
    radius: int,
) -> None:  # fmt: skip
    for p in people:
        centre = _px([[p.x, p.y]], spec, scale)[0]
        cv2.circle(img, tuple(centre), radius * 16, colours[p.id], -1, cv2.LINE_AA, shift=4)
        cv2.circle(img, tuple(centre), radius * 16, (255, 255, 255), 1, cv2.LINE_AA, shift=4)
        if p.theta is not None:
            tip = _px([[p.x + 0.6 * np.cos(p.theta), p.y + 0.6 * np.sin(p.theta)]], spec, scale)[0]
            cv2.arrowedLine(img, tuple(centre), tuple(tip), colours[p.id], 2, cv2.LINE_AA, shift=4, tipLength=0.3)


def _draw_labels(
    img: np.ndarray, spec: GridSpec, scale: int, people: Sequence[Person], colours: dict[int, tuple[int, int, int]],
    radius: int, avoid: np.ndarray,
) -> None:  # fmt: skip
    """Each person's id ("id?" when the facing is unknown) in their colour on a white tag, placed inside the map
    clear of the other tags and of the ``avoid`` pixels of the map (h, w)."""
    texts = [str(p.id) if p.theta is not None else f"{p.id}?" for p in people]
    sizes = [(w + 6, h + base + 4) for (w, h), base in (cv2.getTextSize(t, FONT, 0.45, 1) for t in texts)]
    boxes, prefer = [], []
    for p, (w, h) in zip(people, sizes, strict=True):
        u, v = world_to_image([[p.x, p.y]], spec, scale)[0] - (MARGIN_LEFT, MARGIN_TOP)
        boxes.append((u - radius, v - radius, u + radius, v + radius))
        back = np.pi + (np.pi / 4 if p.theta is None else p.theta)  # behind the person, up-right when unknown
        reach = radius + 3 + max(w, h) / 2
        prefer.append((int(u + reach * np.cos(back) - w / 2), int(v - reach * np.sin(back) - h / 2)))
    corners = place_labels(sizes, boxes, avoid.shape, gap=2, avoid=avoid, prefer=prefer)
    for p, text, (w, h), (u, v) in zip(people, texts, sizes, corners, strict=True):
        u, v = u + MARGIN_LEFT, v + MARGIN_TOP
        cv2.rectangle(img, (u, v), (u + w - 1, v + h - 1), (255, 255, 255), -1)
        cv2.rectangle(img, (u, v), (u + w - 1, v + h - 1), colours[p.id], 1)
        _text(img, text, (u + 3, v + h - 5), 0.45, colours[p.id], 1)


def _draw_groups(
    img: np.ndarray, spec: GridSpec, scale: int, groups: Sequence[Group], people: Sequence[Person],
    margin: float | None,
) -> dict[str, bool]:  # fmt: skip
    """Each group in its colour: the interaction zone (members' hull grown by ``margin``, as the social layer and
    the metrics use it; not drawn when None), the o-space as the group's record holds it (``zone``: a polygon or a
    segment; a point, or a zone under 10 px across (the interest point's mark would hide it), as a ring around the
    mark) and the interest point. Returns which legend entries were drawn."""
    by_id = {p.id: p for p in people}
    drawn = dict.fromkeys(LEGEND, False)
    for i, group in enumerate(groups):
        colour = GROUP_COLOURS[i % len(GROUP_COLOURS)]
        if margin is not None and all(m in by_id for m in group.members):
            outline = group_zone_polygon(group, by_id, margin)  # a Point or LineString when it has no area
            ring = _px(shapely.get_coordinates(outline.boundary if outline.area > 0 else outline), spec, scale)
            cv2.polylines(img, [ring], outline.area > 0, colour, 2, cv2.LINE_AA, shift=4)
            drawn["interaction zone (costmap)"] = True
        zone = _px(np.asarray(group.zone, dtype=float).reshape(-1, 2), spec, scale)
        if len(zone) and np.ptp(zone, axis=0).max() >= 10 * 16:
            cv2.polylines(img, [zone], True, colour, 1, cv2.LINE_AA, shift=4)
            drawn["o-space (the group's zone)"] = True
        elif len(zone):  # one point, or smaller than 10 px
            cv2.circle(img, tuple(np.rint(zone.mean(axis=0)).astype(int)), 7 * 16, colour, 1, cv2.LINE_AA, shift=4)
            drawn["o-space: one point, or under 10 px"] = True
        centre = (_px([group.interest_point], spec, scale)[0] // 16).tolist()
        cv2.drawMarker(img, tuple(centre), colour, cv2.MARKER_CROSS, 10, 2, cv2.LINE_AA)
        drawn["interest point"] = True
    return drawn


def _draw_robot(img: np.ndarray, spec: GridSpec, scale: int, robot: RobotTask) -> None:
    x, y, yaw = robot.start
    r = int(round(robot.radius * scale / spec.resolution * 16))
    centre = _px([[x, y]], spec, scale)[0]
    nose = _px([[x + robot.radius * np.cos(yaw), y + robot.radius * np.sin(yaw)]], spec, scale)[0]
    cv2.circle(img, tuple(centre), r, START, 2, cv2.LINE_AA, shift=4)
    cv2.line(img, tuple(centre), tuple(nose), START, 2, cv2.LINE_AA, shift=4)
    goal = (_px([robot.goal[:2]], spec, scale)[0] // 16).tolist()
    cv2.drawMarker(img, tuple(goal), GOAL, cv2.MARKER_TILTED_CROSS, 16, 3, cv2.LINE_AA)


def render_costmap(
    source: LayeredCostmap | Costmap2D,
    people: Sequence[Person] | None = None,
    groups: Sequence[Group] | None = None,
    *,
    scale: int | None = None,
    robot: RobotTask | None = None,
    scan: LaserScan | None = None,
    title: str | None = None,
    body_radius: float | None = None,
    zone_margin: float | None = None,
    camera: CameraView | None = None,
    outlines: Sequence[Outline] = (),
    extras: Sequence[Extra] = (),
    colours: Mapping[int, tuple[int, int, int]] | None = None,
) -> np.ndarray:
    """A readable BGR picture of a costmap (world y up) with people, groups, robot task, camera and colour scale.

    ``outlines``: shapes of the known map (e.g. a scenario's declared obstacles), each (world points (N, 2), closed),
    drawn as lines over the costs, so a shape shows whole whatever the scan saw of it. ``extras``: what else the
    caller draws (paths, a robot), drawn over the rest before the id labels, each with its legend entry.

    With a LayeredCostmap, its combined grid is drawn; people, groups and scan default to the inputs it last applied,
    body radius to its social layer's, and each group's interaction zone is drawn with the social layer's margin
    (or the default margin the metrics use, without one). A plain Costmap2D draws the interaction zone only when
    ``zone_margin`` is given. ``scale``: pixels per cell (default: a map about 800 px wide). ``colours``: each
    person's colour (BGR) by id in place of their group's (``person_colours``); the legend then names no colour of
    people, which the caller's ``extras`` do.
    """
    if isinstance(source, LayeredCostmap):
        costmap = source.master
        people = source.inputs.get(PEOPLE) if people is None else people
        groups = source.inputs.get(GROUPS) if groups is None else groups
        scan = source.inputs.get(SCAN_INPUT) if scan is None else scan
        social = next((layer for layer in source.layers if isinstance(layer, SocialLayer)), None)
        if social is not None:
            body_radius = social.body_radius if body_radius is None else body_radius
        margin = social.params.group_margin if social is not None else SocialParams().group_margin
        zone_margin = margin if zone_margin is None else zone_margin
    else:
        costmap = source
    spec = costmap.spec
    scale = default_scale(spec) if scale is None else int(scale)
    if scale < 1:
        raise InputError(f"render scale must be >= 1 pixel per cell, got {scale}")
    people, groups = list(people or []), list(groups or [])
    body_radius = 0.2 if body_radius is None else body_radius
    radius = max(3, int(round(body_radius * scale / spec.resolution)))
    own_colours = colours is not None
    colours = dict(person_colours(people, groups) if colours is None else colours)

    w_px, h_px = spec.width * scale, spec.height * scale
    img = np.full((MARGIN_TOP + h_px + MARGIN_BOTTOM, MARGIN_LEFT + w_px + 20, 3), 255, dtype=np.uint8)
    tiles = COST_COLOURS[np.flipud(costmap.costs)]
    img[MARGIN_TOP : MARGIN_TOP + h_px, MARGIN_LEFT : MARGIN_LEFT + w_px] = cv2.resize(
        tiles, (w_px, h_px), interpolation=cv2.INTER_NEAREST
    )
    cv2.rectangle(img, (MARGIN_LEFT - 1, MARGIN_TOP - 1), (MARGIN_LEFT + w_px, MARGIN_TOP + h_px), TEXT, 1)
    if camera is not None:
        _draw_camera(img, spec, scale, camera)
    _draw_outlines(img, spec, scale, outlines)
    ground = img.copy()  # what the labels may cover: costs, the camera's view, outlines
    hits = np.zeros((0, 2)) if scan is None else scan.hit_points()  # world (x, y) of the returns, metres
    for u, v in world_to_image(hits, spec, scale).astype(int):
        _scan_dot(img, int(u), int(v))
    drawn = _draw_groups(img, spec, scale, groups, people, zone_margin)
    _draw_people(img, spec, scale, people, colours, radius)
    if robot is not None:
        _draw_robot(img, spec, scale, robot)
    for extra in extras:
        extra.draw(img, spec, scale)
    on_map = (slice(MARGIN_TOP, MARGIN_TOP + h_px), slice(MARGIN_LEFT, MARGIN_LEFT + w_px))
    _draw_labels(img, spec, scale, people, colours, radius, np.any(img[on_map] != ground[on_map], axis=2))
    _axes(img, spec, scale)
    drawn |= {
        "unknown facing: id?": any(p.theta is None for p in people),
        "known obstacle": bool(outlines),
        "LiDAR hits": len(hits) > 0,
        "robot start": robot is not None,
        "goal": robot is not None,
        "camera, field of view": camera is not None,
    }
    rows = _legend_rows(people, groups, drawn, extras, people_rows=not own_colours)
    panel_w, panel_h = _panel_size(costmap.costs, rows)
    canvas = np.full(
        (max(img.shape[0], MARGIN_TOP + panel_h, PANEL_HEIGHT), MARGIN_LEFT + w_px + panel_w, 3), 255, np.uint8
    )
    canvas[: img.shape[0], : img.shape[1]] = img  # the map, its axes and the last tick's label
    _panel(canvas, spec, scale, costmap.costs, rows)
    if title:
        _text(canvas, title, (MARGIN_LEFT, 26), 0.6, TEXT, 1)
    return canvas
