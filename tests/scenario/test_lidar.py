"""The simulated LiDAR: ranges to walls, circles, boxes and people; no return is inf."""

from __future__ import annotations

import numpy as np
import pytest

from sid.perception.people import Person
from sid.scenario.lidar import simulate_scan
from sid.scenario.obstacles import BoxObstacle, CircleObstacle, SegmentObstacle


def test_simulated_scan_hits_walls_circles_boxes_and_people_at_the_right_range():
    obstacles = [
        SegmentObstacle(((3.0, -5.0), (3.0, 5.0))),
        CircleObstacle((0.0, 2.0), 0.5),
        BoxObstacle((-3.0, -1.0), (-2.0, 1.0)),
    ]
    people = [Person(1, 0.0, -1.5)]
    scan = simulate_scan((0.0, 0.0, 0.0), obstacles, people, beams=360, range_max=10.0, body_radius=0.2)
    angles = scan.angles
    r = dict(zip(np.round(np.rad2deg(angles)).astype(int), scan.ranges, strict=True))
    assert r[0] == pytest.approx(3.0)  # the wall
    assert r[45] == pytest.approx(3.0 * np.sqrt(2))
    assert r[90] == pytest.approx(1.5)  # circle surface
    assert r[-180] == pytest.approx(2.0)  # box face
    assert r[-90] == pytest.approx(1.3)  # body surface


def test_simulated_scan_reports_no_return_as_inf():
    scan = simulate_scan((0.0, 0.0, 0.0), [SegmentObstacle(((5.0, -1.0), (5.0, 1.0)))], beams=8, range_max=4.0)
    assert np.isinf(scan.ranges).all()
