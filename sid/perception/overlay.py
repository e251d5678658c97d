"""Overlay pictures: pose detections (skeletons, boxes, detection scores) and facing arrows on a colour image.

Colours (BGR): the person's left side orange, right side blue, centre line (nose, shoulders and hips links) white,
boxes green. Facing arrows are a top view laid on the image: "up" is away from the camera (world +x), "right"
is the camera's right (world -y); a person facing the camera gets an arrow pointing down.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from sid.labels import place_labels
from sid.perception.keypoints import COCO_KEYPOINTS, LEFT_SHOULDER, RIGHT_SHOULDER, SKELETON, PoseDetection
from sid.perception.people import Person
from sid.perception.pose.base import check_color_image

__all__ = [
    "ARROW_COLOUR",
    "BOX_COLOUR",
    "CENTRE_COLOUR",
    "FONT",
    "LEFT_COLOUR",
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
    """
    image = cv2.cvtColor(check_color_image(color_rgb), cv2.COLOR_RGB2BGR)
    if people is not None and len(people) != len(detections):
        raise ValueError(f"overlay: {len(people)} people for {len(detections)} detections; they must match 1:1")
    h, w = image.shape[:2]
    thick = max(1, round(min(h, w) / 240))
    font_scale = 0.3 * thick
    people = [None] * len(detections) if people is None else people
    labels = []
    for det, person in zip(detections, people, strict=True):
        box = det.box
        cv2.rectangle(image, _pt(box[:2]), _pt(box[2:]), BOX_COLOUR, thick, cv2.LINE_AA)
        ok = _confident(det, keypoint_threshold)
        for a, b in SKELETON:
            if ok[a] and ok[b]:
                cv2.line(image, _pt(det.keypoints[a]), _pt(det.keypoints[b]), _bone_colour(a, b), thick, cv2.LINE_AA)
        for k in np.flatnonzero(ok):
            cv2.circle(image, _pt(det.keypoints[k]), thick + 2, _side_colour(int(k)), cv2.FILLED, cv2.LINE_AA)
            cv2.circle(image, _pt(det.keypoints[k]), thick + 2, (0, 0, 0), 1, cv2.LINE_AA)
        lines = [f"score {det.box_score:.2f}"]
        if person is not None:
            name, where = person_label(person)
            lines = [f"{name}  {lines[0]}", where]
        labels.append(lines)
    arrows = np.zeros((h, w), np.uint8)  # the arrows' pixels, which the labels keep clear of
    for det, person in zip(detections, people, strict=True):
        if person is not None and person.theta is not None:
            _draw_arrow(arrows, det, person.theta, _confident(det, keypoint_threshold), thick, 255)
    sizes = [_block_size(lines, font_scale) for lines in labels]
    corners = place_labels(sizes, [det.box for det in detections], (h, w), avoid=arrows > 0)
    for lines, (left, top) in zip(labels, corners, strict=True):
        _draw_block(image, lines, left, top, font_scale)
    for det, person in zip(detections, people, strict=True):  # arrows last, over every label
        if person is not None and person.theta is not None:
            _draw_arrow(image, det, person.theta, _confident(det, keypoint_threshold), thick, ARROW_COLOUR)
    return image


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
