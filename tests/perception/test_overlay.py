"""Overlay drawing: skeleton, boxes, scores and facing arrows land where the records say, and the legend below the
image lists exactly what is drawn."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from sid.labels import place_labels
from sid.perception.keypoints import KP, PoseDetection
from sid.perception.overlay import (
    ARROW_COLOUR,
    BOX_COLOUR,
    CENTRE_COLOUR,
    FONT,
    LEFT_COLOUR,
    LEGEND,
    LEGEND_BACKGROUND,
    MIN_LEGEND_SCALE,
    RIGHT_COLOUR,
    draw_detections,
    person_label,
)
from sid.perception.people import Person


def _standing(u: float, scores: float = 0.9) -> PoseDetection:
    """A stick figure seen from the front, centred on column u (its left side on the image's right)."""
    keypoints = np.zeros((17, 2))
    rows = {"nose": 160, "eye": 155, "ear": 158, "shoulder": 200, "elbow": 250, "wrist": 300}
    rows |= {"hip": 310, "knee": 390, "ankle": 470}
    for name, index in KP.items():
        part = name.split("_")[-1]
        side = 0 if name == "nose" else (25 if name.startswith("left") else -25)
        keypoints[index] = (u + side, rows[part])
    return PoseDetection(keypoints, np.full(17, scores), (u - 50, 140, u + 50, 480), 0.87)


def _has(image: np.ndarray, colour, v: int, u: int, radius: int = 2) -> bool:
    patch = image[v - radius : v + radius + 1, u - radius : u + radius + 1].reshape(-1, 3)
    return bool(np.any(np.all(patch == colour, axis=1)))


def test_keypoints_bones_and_boxes_are_drawn_in_their_colours():
    color = np.zeros((500, 600, 3), np.uint8)
    person = _standing(200)
    picture = draw_detections(color, [person])
    assert picture.shape[1:] == color.shape[1:] and picture.shape[0] > color.shape[0] and picture.dtype == np.uint8
    assert np.all(picture[500:, :8] == LEGEND_BACKGROUND)  # the legend's band below the image
    u, v = person.keypoints[KP["left_knee"]].astype(int)
    assert _has(picture, LEFT_COLOUR, v, u)
    u, v = person.keypoints[KP["right_knee"]].astype(int)
    assert _has(picture, RIGHT_COLOUR, v, u)
    assert _has(picture, CENTRE_COLOUR, 200, 200)  # the shoulder line between two sides
    assert _has(picture, BOX_COLOUR, 300, 150, radius=1)  # the box's left edge
    assert _has(picture, LEFT_COLOUR, 350, 225)  # the left thigh, halfway from hip to knee
    assert np.all(color == 0)  # the input is not drawn on


def test_low_score_keypoints_are_left_out():
    person = _standing(300, scores=0.1)
    picture = draw_detections(np.zeros((500, 600, 3), np.uint8), [person], keypoint_threshold=0.3)
    u, v = person.keypoints[KP["left_knee"]].astype(int)
    assert not _has(picture, LEFT_COLOUR, v, u)
    assert _has(picture, BOX_COLOUR, 300, 250, radius=1)  # the box is still drawn


def test_output_is_bgr():
    color = np.zeros((100, 100, 3), np.uint8)
    color[..., 0] = 255  # pure red in RGB
    picture = draw_detections(color, [])[:100, :100]  # the image; the legend's band is below it
    assert np.all(picture[..., 2] == 255) and np.all(picture[..., 0] == 0)


@pytest.mark.parametrize(("theta", "direction"), [(0.0, (0, -1)), (np.pi, (0, 1)), (np.pi / 2, (-1, 0))])
def test_facing_arrow_points_along_theta_in_a_top_view(theta, direction):
    person = _standing(300)
    picture = draw_detections(np.zeros((500, 600, 3), np.uint8), [person], [Person(4, 2.0, 0.0, theta)])
    anchor = np.array([300, 200])  # between the shoulders
    tip = anchor + 0.25 * 340 * 0.8 * np.array(direction)  # 80 % along the arrow
    assert _has(picture, ARROW_COLOUR, int(tip[1]), int(tip[0]))
    opposite = anchor - 0.25 * 340 * 0.8 * np.array(direction)
    assert not _has(picture, ARROW_COLOUR, int(opposite[1]), int(opposite[0]))


def test_person_labels_and_unknown_facing():
    assert person_label(Person(3, 3.0, 4.0, np.pi / 2)) == ("id 3", "5.00 m +90 deg")
    assert person_label(Person(1, 2.0, 0.0, None)) == ("id 1", "2.00 m ?")
    picture = draw_detections(np.zeros((500, 600, 3), np.uint8), [_standing(300)], [Person(1, 2.0, 0.0, None)])
    assert not np.any(np.all(picture == ARROW_COLOUR, axis=-1))


def test_people_must_match_detections():
    with pytest.raises(ValueError, match="match 1:1"):
        draw_detections(np.zeros((10, 10, 3), np.uint8), [], [Person(0, 1.0, 0.0)])
    picture = draw_detections(np.zeros((500, 600, 3), np.uint8), [_standing(300)], [None])
    assert not np.any(np.all(picture == ARROW_COLOUR, axis=-1))


def _disjoint(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> bool:
    return a[2] <= b[0] or b[2] <= a[0] or a[3] <= b[1] or b[3] <= a[1]


def test_labels_of_neighbours_do_not_overlap_and_stay_over_their_boxes():
    """Five people side by side with labels wider than their boxes, two cut by the image's top and left edges."""
    boxes = [(-20, 5, 90, 400), (60, 40, 170, 420), (150, 10, 260, 400), (240, 40, 350, 420), (330, 30, 440, 420)]
    sizes = [(150, 40)] * len(boxes)
    corners = place_labels(sizes, boxes, (480, 460))
    blocks = [(u, v, u + w, v + h) for (u, v), (w, h) in zip(corners, sizes, strict=True)]
    for i, a in enumerate(blocks):
        assert min(a[:2]) >= 0 and a[2] <= 460 and a[3] <= 480  # inside the image
        assert boxes[i][0] <= (a[0] + a[2]) / 2 <= boxes[i][2]  # centred over its own box's columns
        assert all(_disjoint(a, b) for b in blocks[i + 1 :]), f"labels {i} and another overlap: {blocks}"
    assert corners[0] == (0, 0)  # a label with room keeps its place above its box, clamped inside the image


def test_overlay_places_neighbouring_labels_apart(monkeypatch):
    import sid.perception.overlay as overlay

    drawn = []
    draw_block = overlay._draw_block

    def record(image, lines, left, top, scale):
        w, h = overlay._block_size(lines, scale)
        if top < 500:  # in the image, not the legend's samples below it
            drawn.append((left, top, left + w, top + h))
        draw_block(image, lines, left, top, scale)

    monkeypatch.setattr(overlay, "_draw_block", record)
    people = [Person(i, 2.0 + i, 0.5 * i, 0.1) for i in range(3)]
    draw_detections(np.zeros((500, 600, 3), np.uint8), [_standing(u) for u in (200, 260, 320)], people)
    assert len(drawn) == 3
    assert all(_disjoint(a, b) for i, a in enumerate(drawn) for b in drawn[i + 1 :]), drawn


def test_labels_keep_clear_of_the_pixels_to_avoid_and_go_to_the_preferred_place():
    avoid = np.zeros((200, 200), bool)
    avoid[80:120, :] = True  # an arrow across the image, right where the label would go
    (corner,) = place_labels([(40, 20)], [(60, 120, 100, 180)], (200, 200), avoid=avoid)
    assert not avoid[corner[1] : corner[1] + 20, corner[0] : corner[0] + 40].any()
    assert corner == (60, 120)  # the nearest free rows (just below the arrow), over its box
    (corner,) = place_labels([(40, 20)], [(60, 120, 100, 180)], (200, 200), prefer=[(20, 185)])
    assert corner == (20, 180)  # the preferred place, kept inside the image


def _only(scores: dict[str, float], u: float = 300) -> PoseDetection:
    """``_standing`` with the keypoints named by a prefix ("left", "right", "nose") scored as given, the rest 0."""
    person = _standing(u)
    person.scores = np.array([next((v for k, v in scores.items() if name.startswith(k)), 0.0) for name in KP])
    return person


LEGEND_CASES = {  # detections and their people -> the legend entries the picture must list
    "nobody": ([], None, []),
    "scores below the threshold": ([_standing(300, scores=0.1)], None, ["box", "score"]),
    "left side only": ([_only({"left": 0.9})], None, ["box", "left", "score"]),
    "right side and nose": ([_only({"right": 0.9, "nose": 0.9})], None, ["box", "right", "centre", "score"]),
    "a person of unknown facing": (
        [_standing(300)],
        [Person(1, 2.0, 0.0, None)],
        ["box", "left", "right", "centre", "score", "id", "where"],
    ),
    "a person facing and an unlabelled detection": (
        [_standing(150), _standing(450)],
        [Person(2, 2.0, 0.5, 0.3), None],
        list(LEGEND),
    ),
}
ELEMENT_COLOURS = {"box": BOX_COLOUR, "left": LEFT_COLOUR, "right": RIGHT_COLOUR, "arrow": ARROW_COLOUR}


@pytest.mark.parametrize("case", LEGEND_CASES)
def test_the_legend_lists_exactly_what_is_drawn(case, monkeypatch) -> None:
    """Each kind of element is listed iff the image shows it (its colour's pixels; label blocks by what was drawn),
    and the legend's band holds the symbol of each entry it lists and no other."""
    import sid.perception.overlay as overlay

    detections, people, expected = LEGEND_CASES[case]
    listed, blocks = [], []
    with_legend, draw_block = overlay._with_legend, overlay._draw_block

    def legend_spy(image, keys, *args):  # type: ignore[no-untyped-def]
        listed.append(list(keys))
        return with_legend(image, keys, *args)

    def block_spy(image, lines, left, top, scale):  # type: ignore[no-untyped-def]
        blocks.append((list(lines), left, top, *overlay._block_size(lines, scale)))
        draw_block(image, lines, left, top, scale)

    monkeypatch.setattr(overlay, "_with_legend", legend_spy)
    monkeypatch.setattr(overlay, "_draw_block", block_spy)
    picture = draw_detections(np.full((500, 600, 3), 100, np.uint8), detections, people)
    assert listed == [expected]
    image, band = picture[:500].copy(), picture[500:]
    labels = [lines for lines, _, top, _, _ in blocks if top < 500]
    assert ("score" in expected) == any("score" in line for lines in labels for line in lines)
    with_id = any(line.startswith("id ") for lines in labels for line in lines)
    assert ("id" in expected) == ("where" in expected) == with_id
    for _, left, top, w, h in blocks:  # label text is white like the centre line: hide it from the colour test
        if top < 500:
            image[max(top, 0) : top + h, max(left, 0) : left + w] = 100
    for key, colour in [*ELEMENT_COLOURS.items(), ("centre", CENTRE_COLOUR)]:
        assert (key in expected) == bool(np.all(image == colour, axis=-1).any()), f"{case}: {key}"
    for key, colour in ELEMENT_COLOURS.items():  # the band's text is white: the centre symbol is not told apart
        assert (key in expected) == bool(np.all(band == colour, axis=-1).any()), f"{case}: the symbol of {key}"
    samples = [lines for lines, _, top, _, _ in blocks if top >= 500]
    assert samples == [[overlay.LABEL_SAMPLES[key]] for key in expected if key in overlay.LABEL_SAMPLES]
    assert picture.shape == (672, 600, 3)  # one size for every overlay of one image size, whatever it lists


def test_the_legend_is_readable_and_whole_on_a_small_image() -> None:
    """A 64 x 48 frame: the legend keeps its minimum font size, the picture widens to hold the longest entry."""
    (_, cap), _ = cv2.getTextSize("X", FONT, MIN_LEGEND_SCALE, 1)
    assert cap >= 9
    people = [Person(1, 2.0, 0.0, 0.5)]
    small = _standing(32)
    small.keypoints, small.box = small.keypoints / 10, np.array(small.box) / 10
    picture = draw_detections(np.zeros((48, 64, 3), np.uint8), [small], people)
    assert picture.shape[1] > 64
    band = picture[48:]
    drawn = np.flatnonzero(np.any(band != LEGEND_BACKGROUND, axis=(0, 2)))
    assert drawn.max() < picture.shape[1] - 4, "legend text cut off at the right edge"
