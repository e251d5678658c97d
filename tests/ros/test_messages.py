"""sid.ros.messages: the rclpy messages built from sid.ros.convert's fields (needs rclpy's message packages)."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("rclpy", reason="rclpy is not installed (pip install 'sid-social[ros]' or source ROS 2)")

from builtin_interfaces.msg import Time  # noqa: E402

from costmap.grid import Costmap2D, GridSpec  # noqa: E402
from sid.ros import messages  # noqa: E402
from sid.ros.convert import MarkerFields, grid_fields  # noqa: E402


def test_occupancy_grid_message() -> None:
    costmap = Costmap2D.filled(GridSpec(0.05, -1.0, 2.0, 4, 3), 0)
    costmap.costs[2, 3] = 254
    msg = messages.occupancy_grid(grid_fields(costmap, "map"), Time(sec=12, nanosec=250_000_000))
    assert msg.header.frame_id == "map" and (msg.header.stamp.sec, msg.header.stamp.nanosec) == (12, 250_000_000)
    assert (msg.info.width, msg.info.height) == (4, 3) and msg.info.resolution == pytest.approx(0.05)
    assert (msg.info.origin.position.x, msg.info.origin.position.y, msg.info.origin.orientation.w) == (-1.0, 2.0, 1.0)
    assert list(msg.data) == [0] * 11 + [100]


def test_marker_array_clears_then_adds() -> None:
    fields = [
        MarkerFields("people", 4, "cylinder", 1.0, 2.0, 0.85, 0.0, (0.4, 0.4, 1.7), (0.1, 0.5, 0.9, 0.8)),
        MarkerFields("group_zones", 1, "line_strip", 0, 0, 0, 0, (0.05, 0, 0), (1, 0, 0, 1), ((0, 0), (1, 0), (0, 0))),
        MarkerFields("facing", 4, "arrow", 1.0, 2.0, 1.0, math.pi / 2, (0.6, 0.06, 0.06), (0, 0, 1, 1)),
    ]
    msg = messages.marker_array(fields, "map", Time(sec=1))
    first, cylinder, strip, arrow = msg.markers
    assert first.action == first.DELETEALL
    assert (cylinder.ns, cylinder.id, cylinder.type, cylinder.header.frame_id) == (
        "people",
        4,
        cylinder.CYLINDER,
        "map",
    )
    assert cylinder.scale.z == pytest.approx(1.7) and cylinder.color.a == pytest.approx(0.8)
    assert [(p.x, p.y) for p in strip.points] == [(0, 0), (1, 0), (0, 0)] and strip.type == strip.LINE_STRIP
    assert np.isclose(arrow.pose.orientation.z, math.sin(math.pi / 4))


def test_optional_message_packages_are_none_when_absent() -> None:
    for found, module in ((messages.filter_info_type(), "nav2_msgs"), (messages.ids_list_type(), "hri_msgs")):
        try:
            __import__(module)
        except ImportError:
            assert found is None
        else:
            assert found is not None
