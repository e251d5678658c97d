"""Overlay pictures: pose detections (skeletons, boxes, detection scores) and facing arrows on a colour image, with
a legend of what is drawn in a band below it.

Colours (BGR): the person's left side orange, right side blue, centre line (nose, shoulders and hips links) white,
boxes green. Facing arrows are a top view of the people's frame laid on the image: "up" is its +x (away from the
camera in ``base_footprint`` with a camera looking ahead), "right" its -y; a person facing the camera gets an arrow
pointing down. Labels give the id, the distance from the frame's origin and the facing yaw in that frame.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from sid.errors import InputError
from sid.labels import place_labels
from sid.perception.keypoints import COCO_KEYPOINTS, LEFT_SHOULDER, RIGHT_SHOULDER, SKELETON, PoseDetection
from sid.perception.people import Person
from sid.perception.pose.base import check_color_image

__all__ = [
    "ARROW_COLOUR",
    "BOX_COLOUR",
    "CENTRE_COLOUR",
    "FONT",
    "LABEL_SAMPLES",
    "LEFT_COLOUR",
    "LEGEND",
    "LEGEND_BACKGROUND",
    "MIN_LEGEND_SCALE",
    "RIGHT_COLOUR",
    "draw_detections",
    "person_label",
]

LEFT_COLOUR = (0, 140, 255)
RIGHT_COLOUR = (255, 140, 0)
CENTRE_COLOUR = (255, 255, 255)
BOX_COLOUR = (60, 200, 60)
ARROW_COLOUR = (0, 255, 255)
FONT = cv2.FONT_HERSHEY_SIMPLEX
LEGEND = {  # every entry the legend can hold, in its order: key -> text
    "box": "detected person",
    "left": "person's left",
    "right": "person's right",
    "centre": "nose, shoulder and hip lines",
    "arrow": "facing, from above (up: +x of frame_id)",
    "score": "detector's confidence",
    "id": "person's id",
    "where": "distance, facing yaw in frame_id (?: unknown)",
}
LABEL_SAMPLES = {"score": "score 0.88", "id": "id 3", "where": "2.41 m -12 deg"}  # the labels' entries show one
MIN_LEGEND_SCALE = 0.45  # font scale of the legend at least (HERSHEY_SIMPLEX: capitals ~10 px high)
LEGEND_BACKGROUND = (70, 70, 70)


def _side_colour(index: int) -> tuple[int, int, int]:
    name = COCO_KEYPOINTS[index]
    return LEFT_COLOUR if name.startswith("left") else RIGHT_COLOUR if name.startswith("right") else CENTRE_COLOUR


def _bone_colour(a: int, b: int) -> tuple[int, int, int]:
    colour_a, colour_b = _side_colour(a), _side_colour(b)
    return colour_a if colour_a == colour_b else CENTRE_COLOUR


def _pt(uv: np.ndarray) -> tuple[int, int]:
    return int(round(float(uv[0]))), int(round(float(uv[1])))


def _block_size(lines: Sequence[str], scale: float) -> tuple[int, int]:
    """Width and height (px) of ``_draw_block``'s lines of text, each on a dark band."""
    sizes = [cv2.getTextSize(text, FONT, scale, 1) for text in lines]
    return max(tw for (tw, _), _ in sizes) + 3, sum(th + base + 3 for (_, th), base in sizes)


def _draw_block(image: np.ndarray, lines: Sequence[str], left: int, top: int, scale: float) -> None:
    """Lines of text on dark bands, the first line lowest, in the block whose top-left corner is (left, top)."""
    bottom = top + _block_size(lines, scale)[1]  # one past the lowest row
    for text in lines:
        (tw, th), base = cv2.getTextSize(text, FONT, scale, 1)
        cv2.rectangle(image, (left, bottom - th - base - 3), (left + tw + 2, bottom - 1), (0, 0, 0), cv2.FILLED)
        cv2.putText(image, text, (left + 1, bottom - base - 2), FONT, scale, (255, 255, 255), 1, cv2.LINE_AA)
        bottom -= th + base + 3


def person_label(person: Person) -> tuple[str, str]:
    """Two label lines: ``id 3`` and ``2.41 m -12 deg`` (horizontal distance from the camera, facing yaw in degrees, "?"
    when unknown)."""
    facing = "?" if person.theta is None else f"{np.degrees(person.theta):+.0f} deg"
    return f"id {person.id}", f"{np.hypot(person.x, person.y):.2f} m {facing}"


def draw_detections(
    color_rgb: np.ndarray,
    detections: Sequence[PoseDetection],
    people: Sequence[Person | None] | None = None,
    keypoint_threshold: float = 0.3,
) -> np.ndarray:
    """Draw detections on a copy of ``color_rgb`` (H, W, 3) RGB uint8; returns a BGR image for ``cv2.imwrite``.

    Keypoints scoring below ``keypoint_threshold`` (and bones touching them) are left out. ``people``, if given,
    matches ``detections`` one to one (None where a detection gave no person): each person gets a facing arrow
    from between the shoulders (or the top of the box) and, above the box, a label with id, distance and yaw.
    Below the image a band lists what is drawn (``LEGEND``'s entries, each with its symbol); the band has one size
    for every call on one image size, and the picture is wider than the image only when the image is narrower than
    the legend's longest entry.
    """
    image = cv2.cvtColor(check_color_image(color_rgb), cv2.COLOR_RGB2BGR)
    if people is not None and len(people) != len(detections):
        raise InputError(f"overlay: {len(people)} people for {len(detections)} detections; they must match 1:1")
    h, w = image.shape[:2]
    thick = max(1, round(min(h, w) / 240))
    font_scale = 0.3 * thick
    people = [None] * len(detections) if people is None else people
    drawn: set[str] = set()
    labels = []
    for det, person in zip(detections, people, strict=True):
        box = det.box
        cv2.rectangle(image, _pt(box[:2]), _pt(box[2:]), BOX_COLOUR, thick, cv2.LINE_AA)
        drawn |= {"box", "score"}
        ok = _confident(det, keypoint_threshold)
        for a, b in SKELETON:
            if ok[a] and ok[b]:
                colour = _bone_colour(a, b)
                cv2.line(image, _pt(det.keypoints[a]), _pt(det.keypoints[b]), colour, thick, cv2.LINE_AA)
                drawn.add(_COLOUR_ENTRY[colour])
        for k in np.flatnonzero(ok):
            colour = _side_colour(int(k))
            cv2.circle(image, _pt(det.keypoints[k]), thick + 2, colour, cv2.FILLED, cv2.LINE_AA)
            cv2.circle(image, _pt(det.keypoints[k]), thick + 2, (0, 0, 0), 1, cv2.LINE_AA)
            drawn.add(_COLOUR_ENTRY[colour])
        lines = [f"score {det.box_score:.2f}"]
        if person is not None:
            name, where = person_label(person)
            lines = [f"{name}  {lines[0]}", where]
            drawn |= {"id", "where"}
        labels.append(lines)
    arrows = np.zeros((h, w), np.uint8)  # the arrows' pixels, which the labels keep clear of
    for det, person in zip(detections, people, strict=True):
        if person is not None and person.theta is not None:
            _draw_arrow(arrows, det, person.theta, _confident(det, keypoint_threshold), thick, 255)
            drawn.add("arrow")
    sizes = [_block_size(lines, font_scale) for lines in labels]
    corners = place_labels(sizes, [det.box for det in detections], (h, w), avoid=arrows > 0)
    for lines, (left, top) in zip(labels, corners, strict=True):
        _draw_block(image, lines, left, top, font_scale)
    for det, person in zip(detections, people, strict=True):  # arrows last, over every label
        if person is not None and person.theta is not None:
            _draw_arrow(image, det, person.theta, _confident(det, keypoint_threshold), thick, ARROW_COLOUR)
    keys = [key for key in LEGEND if key in drawn]
    return _with_legend(image, keys, max(font_scale, MIN_LEGEND_SCALE), font_scale, thick)


_COLOUR_ENTRY = {LEFT_COLOUR: "left", RIGHT_COLOUR: "right", CENTRE_COLOUR: "centre"}
_NOTHING = "no person detected"


def _swatch_width(key: str | None, scale: float, label_scale: float) -> int:
    """Width (px) of legend entry ``key``'s symbol and the gap after it: a label's sample as drawn, else a fixed
    width."""
    if key in LABEL_SAMPLES:
        return _block_size([LABEL_SAMPLES[key]], label_scale)[0] + round(6 * scale / 0.45)
    return round(30 * scale / 0.45)


def _legend_layout(
    keys: Sequence[str | None], texts: Sequence[str], width: int, scale: float, label_scale: float
) -> tuple[list[tuple[int, int]], int, int]:
    """Where each legend entry (symbol and text) goes in a band ``width`` px wide: top-left corners filled in rows
    left to right, the band's width (wider than ``width`` only when one entry is) and height."""
    pad = round(8 * scale / 0.45)
    row = max(round(20 * scale / 0.45), _block_size(["0"], label_scale)[1] + 4)
    widths = [
        _swatch_width(key, scale, label_scale) + cv2.getTextSize(text, FONT, scale, 1)[0][0]
        for key, text in zip(keys, texts, strict=True)
    ]
    band = max([width, *(w + 2 * pad for w in widths)])
    corners, u, v = [], pad, pad // 2
    for entry in widths:
        if u > pad and u + entry + pad > band:
            u, v = pad, v + row
        corners.append((u, v))
        u += entry + 2 * pad
    return corners, band, v + row + pad // 2


def _with_legend(image: np.ndarray, keys: Sequence[str], scale: float, label_scale: float, thick: int) -> np.ndarray:
    """``image`` with a grey band below it that lists ``keys`` (of ``LEGEND``), each with its symbol as drawn. The
    band is as high as the whole legend needs, so every overlay of one image size has one size; when nothing is
    drawn it says so."""
    h, w = image.shape[:2]
    everything: list[str | None] = [*LEGEND, None]
    _, band_w, band_h = _legend_layout(everything, [*LEGEND.values(), _NOTHING], w, scale, label_scale)
    out = np.zeros((h + band_h, band_w, 3), np.uint8)
    out[:h, :w] = image
    out[h:] = LEGEND_BACKGROUND
    shown: list[str | None] = [*keys] if keys else [None]
    texts = [_NOTHING if key is None else LEGEND[key] for key in shown]
    corners, _, _ = _legend_layout(shown, texts, band_w, scale, label_scale)
    row = max(round(20 * scale / 0.45), _block_size(["0"], label_scale)[1] + 4)
    (_, text_h), _ = cv2.getTextSize("X", FONT, scale, 1)
    for key, text, (u, v) in zip(shown, texts, corners, strict=True):
        top, mid = h + v + 2, h + v + row // 2
        swatch = _swatch_width(key, scale, label_scale) if key is not None else 0
        if key is not None:
            _legend_symbol(out, key, (u, top, u + swatch - round(6 * scale / 0.45), mid), thick, label_scale)
        cv2.putText(out, text, (u + swatch, mid + text_h // 2), FONT, scale, (255, 255, 255), 1, cv2.LINE_AA)
    return out


def _legend_symbol(
    image: np.ndarray, key: str, cell: tuple[int, int, int, int], thick: int, label_scale: float
) -> None:
    """The symbol of legend entry ``key`` drawn as the element it stands for, in the cell (u0, v0, u1, v_mid)."""
    u0, v0, u1, mid = cell
    if key == "box":
        cv2.rectangle(image, (u0 + 2, v0 + 1), (u1 - 2, 2 * mid - v0 - 1), BOX_COLOUR, thick, cv2.LINE_AA)
    elif key in _COLOUR_ENTRY.values():
        colour = next(c for c, k in _COLOUR_ENTRY.items() if k == key)
        cv2.line(image, (u0 + 4, mid), (u1 - 4, mid), colour, thick, cv2.LINE_AA)
        for u in (u0 + 4, u1 - 4):
            cv2.circle(image, (u, mid), thick + 2, colour, cv2.FILLED, cv2.LINE_AA)
            cv2.circle(image, (u, mid), thick + 2, (0, 0, 0), 1, cv2.LINE_AA)
    elif key == "arrow":
        u = (u0 + u1) // 2
        cv2.arrowedLine(image, (u, 2 * mid - v0), (u, v0), ARROW_COLOUR, thick + 1, cv2.LINE_AA, tipLength=0.35)
    else:  # a label: its sample on a dark band, as drawn over the boxes
        _, height = _block_size([LABEL_SAMPLES[key]], label_scale)
        _draw_block(image, [LABEL_SAMPLES[key]], u0, mid - height // 2, label_scale)


def _confident(det: PoseDetection, threshold: float) -> np.ndarray:
    return (det.scores >= threshold) & np.all(np.isfinite(det.keypoints), axis=1)


def _draw_arrow(
    image: np.ndarray, det: PoseDetection, theta: float, ok: np.ndarray, thick: int, colour: int | tuple[int, int, int]
) -> None:
    """Facing arrow (world yaw ``theta``) in ``colour`` from between the shoulders (or the top of the box), a quarter
    of the box height long."""
    box = det.box
    if ok[LEFT_SHOULDER] and ok[RIGHT_SHOULDER]:
        anchor = (det.keypoints[LEFT_SHOULDER] + det.keypoints[RIGHT_SHOULDER]) / 2
    else:
        anchor = np.array([(box[0] + box[2]) / 2, box[1]])
    tip = anchor + 0.25 * (box[3] - box[1]) * np.array([-np.sin(theta), -np.cos(theta)])
    cv2.arrowedLine(image, _pt(anchor), _pt(tip), colour, thick + 1, cv2.LINE_AA, tipLength=0.3)
