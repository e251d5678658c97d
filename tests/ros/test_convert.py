"""sid.ros.convert and the keepout mask it publishes, without ROS: message fields, and the costs Nav2 reads back."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from shapely.geometry import Polygon

from costmap.export import filter_mask_cost, keepout_mask
from costmap.grid import Costmap2D, GridSpec
from costmap.layers.social import group_zone_polygon
from costmap.occupancy import occupancy_to_cost
from sid.ros.convert import grid_fields, groups_document, quaternion_from_yaw, scene_markers, yaw_from_quaternion
from sid.tracking.records import MotionState, TrackedGroup, TrackedPerson

SPEC = GridSpec.from_size(0.1, (-1.0, 2.0), (3.0, 2.0))  # 30 x 20 cells, lower-left corner at (-1, 2)


def person(pid: int, x: float, y: float, theta: float | None, state: MotionState = "standing") -> TrackedPerson:
    return TrackedPerson(pid, x, y, 0.0, 0.0, theta, state, True, True, 0.0, pid, 0.1, 0.0 if theta is None else 1.0)


def test_grid_fields_are_the_occupancy_grid_message_layout() -> None:
    costmap = Costmap2D.filled(SPEC, 0)
    costmap.costs[3, 7] = 254  # row 3 = y 2.3..2.4, column 7 = x -0.3..-0.2
    costmap.costs[0, 0] = 240
    costmap.costs[19, 29] = 255
    fields = grid_fields(costmap, "map")
    assert (fields.frame_id, fields.width, fields.height) == ("map", 30, 20)
    assert fields.resolution == pytest.approx(0.1)
    assert (fields.origin_x, fields.origin_y, fields.origin_orientation) == (-1.0, 2.0, (0.0, 0.0, 0.0, 1.0))
    assert fields.data.dtype == np.int8 and fields.data.shape == (600,)
    assert fields.data[3 * 30 + 7] == 100  # row-major, row 0 = lowest y
    assert fields.data[0] == 94 and fields.data[-1] == -1
    assert np.count_nonzero(fields.data) == 3


def test_keepout_filter_reads_the_costs_back_within_a_quantisation_step() -> None:
    costs = np.arange(256, dtype=np.uint8).reshape(16, 16)
    spec = GridSpec(0.05, 0.0, 0.0, 16, 16)
    mask = keepout_mask(Costmap2D(spec, costs))
    read = filter_mask_cost(mask.data)
    known = costs != 255
    assert np.all(np.abs(read[known].astype(int) - costs[known].astype(int)) <= 1.27)
    assert read[costs == 255].tolist() == [255]  # unknown: the filter leaves the cell alone
    assert read[costs == 254].tolist() == [254] and read[costs == 0].tolist() == [0]
    assert read[costs == 240].tolist() == [239]  # a group zone
    # Nav2's costmap_2d rounding: 25 * 2.54 = 63.5 -> 64 (half away from zero).
    assert filter_mask_cost(np.array([25, 99, 100, -1], np.int8)).tolist() == [64, 251, 254, 255]
    with pytest.raises(ValueError, match="-1..100"):
        filter_mask_cost(np.array([101], np.int16))


def test_the_static_layer_trap_trinary_turns_the_zone_into_free_space() -> None:
    """Read by a StaticLayer with its default trinary_costmap: true, the mask loses every graded cost."""
    costmap = Costmap2D.filled(GridSpec(0.1, 0.0, 0.0, 3, 1), 0)
    costmap.costs[0] = [240, 120, 254]
    mask = keepout_mask(costmap).data
    assert occupancy_to_cost(mask, trinary=True).tolist() == [[0, 0, 254]]
    assert occupancy_to_cost(mask, trinary=False).tolist() == [[238, 119, 254]]


def test_yaw_quaternion_round_trip() -> None:
    for yaw in np.linspace(-math.pi + 1e-6, math.pi, 13):
        assert yaw_from_quaternion(*quaternion_from_yaw(float(yaw))) == pytest.approx(yaw)


def test_markers_and_groups_document() -> None:
    people = [person(1, 1.0, 0.5, 0.0), person(2, 2.0, 0.5, math.pi), person(3, 3.0, 3.0, None, "walking")]
    zone = np.array([[1.4, 0.4], [1.6, 0.4], [1.5, 0.6]])
    group = TrackedGroup(7, "conversation", (1, 2), (1.5, 0.5), zone, 0.02, 0.5, (0.0, 0.0), 0.0)
    markers = scene_markers(people, [group])
    kinds = {(m.namespace, m.id): m for m in markers}
    assert kinds[("people", 3)].kind == "cylinder" and kinds[("people", 3)].z == pytest.approx(0.85)
    assert kinds[("facing", 2)].yaw == pytest.approx(math.pi)
    assert ("facing", 3) not in kinds  # unknown facing: no arrow
    # The zone the mask paints: the hull of the o-space polygon and the members, grown by the social margin (0.3 m).
    outline = kinds[("group_zones", 7)].points
    expected = group_zone_polygon(group.as_group(), {p.id: p.as_person() for p in people}, 0.3)
    assert outline[0] == outline[-1] and Polygon(outline).symmetric_difference(expected).area < 1e-9
    assert Polygon(outline).area > 1.0 * 0.6 + math.pi * 0.3**2  # at least the stadium round the two members
    pair = TrackedGroup(8, "conversation", (1, 2), (1.5, 0.5), np.array([[1.5, 0.5]]), 0.0, 0.5, (0.0, 0.0), 0.0)
    assert ("group_zones", 8) in {(m.namespace, m.id) for m in scene_markers(people, [pair])}  # a point: none before
    assert kinds[("group_ids", 7)].text == "group 7: 1, 2"
    document = json.loads(json.dumps(groups_document(12.5, "map", people, [group])))
    assert document["frame_id"] == "map" and document["stamp"] == 12.5
    assert document["people"][2] == {
        "id": 3,
        "x": 3.0,
        "y": 3.0,
        "theta": None,
        "vx": 0.0,
        "vy": 0.0,
        "state": "walking",
    }
    (g,) = document["groups"]
    assert g["id"] == 7 and g["kind"] == "conversation" and g["members"] == [1, 2]
    assert g["interest_point"] == [1.5, 0.5] and len(g["zone"]) == 3
