"""Costmap pictures: people coloured by group, each group's o-space as its record holds it, id labels clear of each
other and of what is drawn, and a legend of exactly what is drawn."""

from __future__ import annotations

import math

import numpy as np
import pytest

import costmap.render as render
from costmap.grid import Costmap2D, GridSpec
from costmap.render import GROUP_COLOURS, PERSON, CameraView, render_costmap, world_to_image
from costmap.scan import LaserScan
from sid.perception.group import Group
from sid.perception.people import Person

SPEC = GridSpec.from_size(0.05, (-0.5, -3.0), (6.0, 6.0))
PAIR = [Person(1, 2.0, 0.35, -np.pi / 2), Person(2, 2.0, -0.35, np.pi / 2)]  # face to face, 0.7 m apart
POINT_GROUP = Group((1, 2), (2.0, 0.0), 0.0, np.array([[2.0, 0.0]]), 0.35)  # a pair's o-space: one point


def _pixel(img: np.ndarray, xy: tuple[float, float], scale: int) -> tuple[int, ...]:
    u, v = np.rint(world_to_image([xy], SPEC, scale)[0]).astype(int)
    return tuple(int(c) for c in img[v, u])


def _near(img: np.ndarray, xy: tuple[float, float], scale: int, colour: tuple[int, ...]) -> bool:
    """Whether ``colour`` is drawn within a pixel of world point ``xy`` (anti-aliased lines blend at their edges)."""
    u, v = np.rint(world_to_image([xy], SPEC, scale)[0]).astype(int)
    return bool(np.any(np.all(img[v - 1 : v + 2, u - 1 : u + 2] == colour, axis=2)))


def test_people_are_coloured_by_group_and_the_legend_names_each_group(legend) -> None:
    people = [*PAIR, Person(3, 4.0, 2.0, 0.0), Person(4, 4.0, -2.0, np.pi), Person(5, 4.6, -2.0, 0.0)]
    trio = Group((4, 5), (4.3, -2.0), 0.0, np.array([[4.3, -2.0]]), 0.3)
    img = render_costmap(Costmap2D.filled(SPEC), people, [POINT_GROUP, trio], scale=4)
    assert _pixel(img, (2.0, 0.35), 4) == _pixel(img, (2.0, -0.35), 4) == GROUP_COLOURS[0]
    assert _pixel(img, (4.0, -2.0), 4) == GROUP_COLOURS[1] and _pixel(img, (4.0, 2.0), 4) == PERSON
    assert legend[-1][:3] == ["person in no group, facing", "group of 1, 2", "group of 4, 5"]


def test_people_alone_of_unknown_facing_are_not_listed_as_facing(legend) -> None:
    """The legend said "person in no group, facing" (a dot and an arrow) for people alone drawn without an arrow."""
    unknown = [Person(3, 4.0, 2.0, None), Person(4, 4.0, -2.0, None)]
    render_costmap(Costmap2D.filled(SPEC), [*PAIR, *unknown], [POINT_GROUP], scale=4)
    assert legend[-1][:2] == ["person in no group", "group of 1, 2"] and "unknown facing: id?" in legend[-1]
    render_costmap(Costmap2D.filled(SPEC), [*PAIR, *unknown, Person(5, 1.0, 2.0, 0.0)], [POINT_GROUP], scale=4)
    assert legend[-1][:2] == ["person in no group, facing", "group of 1, 2"] and "unknown facing: id?" in legend[-1]


def test_a_group_whose_ids_do_not_fit_the_legend_is_named_by_its_size_in_people(legend) -> None:
    ring = [Person(7 + k, 3.0 + math.cos(k), math.sin(k), k + math.pi) for k in range(6)]  # ids 7..12
    group = Group(tuple(p.id for p in ring), (3.0, 0.0), 1.0, np.array([[3.0, 0.0]]), 0.3)
    render_costmap(Costmap2D.filled(SPEC), ring, [group], scale=2)
    assert legend[-1][0] == "group of 6 people"  # not "group of 6", which reads as person 6's group


def test_a_zone_of_one_point_is_drawn_as_a_point_and_the_hull_only_with_a_margin(legend) -> None:
    camera = CameraView(0.0, 0.0, 0.0, 1.5)
    top = render_costmap(Costmap2D.filled(SPEC), PAIR, [POINT_GROUP], scale=4, camera=camera)
    ring = (2.0 + 7 / 4 * SPEC.resolution, 0.0)  # the point's ring, 7 px out
    hull = (2.0 + 0.3, 0.0)  # where the members' hull grown by 0.3 m crosses the x axis
    assert _near(top, ring, 4, GROUP_COLOURS[0]) and not _near(top, hull, 4, GROUP_COLOURS[0])
    assert legend[-1] == [
        "group of 1, 2",
        "o-space: one point, or under 10 px",
        "interest point",
        "camera, field of view",
    ]
    grown = render_costmap(Costmap2D.filled(SPEC), PAIR, [POINT_GROUP], scale=4, zone_margin=0.3)
    columns = [_pixel(grown, (2.0 + 0.3 + dx, 0.0), 4) for dx in np.linspace(-0.03, 0.03, 7)]
    assert GROUP_COLOURS[0] in columns and "interaction zone (costmap)" in legend[-1]


def test_id_labels_keep_clear_of_each_other_and_of_what_is_drawn(monkeypatch) -> None:
    """Five people shoulder to shoulder, each facing the next: every label on free map, none touching another."""
    placed: list[tuple[list, list, np.ndarray]] = []
    place = render.place_labels

    def spy(sizes, boxes, shape, gap=1, avoid=None, prefer=None):  # type: ignore[no-untyped-def]
        corners = place(sizes, boxes, shape, gap, avoid, prefer)
        placed.append((list(sizes), corners, avoid))
        return corners

    monkeypatch.setattr(render, "place_labels", spy)
    people = [Person(i, 2.0 + 0.45 * i, 0.1 * (i % 2), 0.0) for i in range(5)]
    render_costmap(Costmap2D.filled(SPEC), people, [], scale=4)
    ((sizes, corners, avoid),) = placed
    blocks = [(u, v, u + w, v + h) for (u, v), (w, h) in zip(corners, sizes, strict=True)]
    for i, (u0, v0, u1, v1) in enumerate(blocks):
        assert not avoid[v0:v1, u0:u1].any(), f"label {i} covers a person or an arrow"
        for a0, b0, a1, b1 in blocks[i + 1 :]:
            assert u1 <= a0 or a1 <= u0 or v1 <= b0 or b1 <= v0, "two labels overlap"


def test_the_legend_names_lidar_hits_only_when_the_scan_has_some(legend) -> None:
    # A scan of an empty map (no obstacles, nobody in range) draws no dot, so the legend has no "LiDAR hits" row.
    ranges = np.full(8, np.inf)
    empty = LaserScan(ranges, -np.pi, np.pi / 4, 10.0, (1.0, 0.0, 0.0))
    render_costmap(Costmap2D.filled(SPEC), scan=empty, scale=2)
    assert "LiDAR hits" not in legend[-1]
    ranges[0] = 1.0
    render_costmap(Costmap2D.filled(SPEC), scan=LaserScan(ranges, -np.pi, np.pi / 4, 10.0, (1.0, 0.0, 0.0)), scale=2)
    assert "LiDAR hits" in legend[-1]


@pytest.mark.parametrize(
    ("origin", "size", "x_ticks", "y_ticks"),
    [
        ((-1.0, -3.5), (11.0, 7.0), range(-1, 11), range(-3, 4)),  # the demo's map: a tick a metre, as before
        ((-1.0, -1.5), (22.0, 3.0), range(-1, 22), [-1.0, 0.0, 1.0]),  # a corridor: was one tick, "-0", on y
        ((0.0, 0.0), (1.0, 0.8), np.arange(0.0, 1.01, 0.2), np.arange(0.0, 0.81, 0.2)),  # was one tick, 0, on y
        ((-20.0, -20.0), (40.0, 40.0), range(-20, 21, 2), range(-20, 21, 2)),  # labels 40 px apart at 1 px a cell
    ],
)
def test_axis_ticks_are_readable_on_every_map_and_never_negative_zero(origin, size, x_ticks, y_ticks) -> None:
    spec = GridSpec.from_size(0.05, origin, size)
    xs, ys = render.axis_ticks(spec, render.default_scale(spec))
    assert xs == pytest.approx(list(x_ticks)) and ys == pytest.approx(list(y_ticks))
    assert all(math.copysign(1.0, t) > 0 for t in (*xs, *ys) if t == 0)  # 0, not -0


@pytest.mark.parametrize("values", [[0], [0, 100], [0, 253, 254, 255], [0, 100, 253, 254, 255], [255]])
@pytest.mark.parametrize("entries", [0, 1, 9])
def test_the_panel_size_is_where_the_panel_draws(values: list[int], entries: int) -> None:
    # _panel_size and _panel lay out the same rows: nothing the panel draws lies beyond its size, and with a legend
    # its last row reaches the last row band.
    spec = GridSpec(0.1, 0.0, 0.0, 10, 10)
    costs = np.resize(np.array(values, np.uint8), spec.shape)
    swatches = list(render.LEGEND.values()) * 2
    rows = [(f"entry {i} " + "x" * 3 * i, swatches[i]) for i in range(entries)]
    width, height = render._panel_size(costs, rows)
    left = render.MARGIN_LEFT + spec.width
    img = np.full((render.MARGIN_TOP + height + 40, left + width + 40, 3), 255, np.uint8)
    render._panel(img, spec, 1, costs, rows)
    drawn_rows, drawn_cols = np.nonzero(np.any(img != 255, axis=2))
    if values == [0] and not entries:
        assert not len(drawn_rows)  # nothing to show
        return
    bottom = drawn_rows.max() - render.MARGIN_TOP
    assert bottom < height and drawn_cols.max() - left < width
    if entries:  # the last legend row ends the panel
        assert bottom > height - render.LEGEND_ROW


def test_given_colours_replace_the_group_colours_and_their_legend_rows(legend) -> None:
    """``colours`` (the F-formation error pictures colour people by how their true group came out): each person in
    theirs, and the legend names no colour of people, which the caller's extras do."""
    colours = {1: (0, 0, 255), 2: (0, 0, 255)}
    img = render_costmap(Costmap2D.filled(SPEC), PAIR, [], scale=4, colours=colours)
    assert _pixel(img, (2.0, 0.35), 4) == _pixel(img, (2.0, -0.35), 4) == (0, 0, 255)
    assert legend[-1] == []


def test_a_dashed_polyline_leaves_gaps_of_its_dash_length_and_turns_corners() -> None:
    img = np.full((40, 200, 3), 255, np.uint8)
    render.dashed_polyline(img, [(10, 20), (110, 20), (110, 35)], False, (0, 0, 0), thickness=1, dash=10)
    row = img[20, 10:110, 0] < 128
    assert 40 <= row.sum() <= 60  # half of 100 px, give or take the anti-aliased ends
    assert row[2:8].all() and not row[13:17].any() and row[22:28].all()
    assert (img[22:35, 110, 0] < 128).any()  # the dash running on round the corner
    closed = np.full((60, 60, 3), 255, np.uint8)
    render.dashed_polyline(closed, [(10, 10), (50, 10), (50, 50), (10, 50)], True, (0, 0, 0), thickness=1, dash=5)
    assert (closed[12:48, 10, 0] < 128).any()  # the closing side back to the first point is drawn
