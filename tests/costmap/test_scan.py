"""The LaserScan record: a pose that is not finite is refused; any finite yaw is an angle."""

from __future__ import annotations

import numpy as np
import pytest

from costmap.scan import LaserScan
from sid.scenario.lidar import simulate_scan


def test_scan_rejects_nan_pose():
    with pytest.raises(ValueError, match="pose"):
        LaserScan(np.array([1.0]), 0.0, 0.1, 5.0, (np.nan, 0.0, 0.0))
    with pytest.raises(ValueError, match="pose"):
        simulate_scan((0.0, np.nan, 0.0), [])


def test_a_huge_yaw_still_spreads_the_beams_round():
    # At yaw 1e308 the offsets of the beams used to vanish in the sum: all 720 beams pointed one way.
    scan = LaserScan(np.ones(720), -np.pi, 2 * np.pi / 720, 5.0, (0.0, 0.0, 1e308))
    steps = np.diff(np.unwrap(scan.angles))
    assert np.allclose(steps, 2 * np.pi / 720)
    turned = LaserScan(np.ones(4), -np.pi, np.pi / 2, 5.0, (0.0, 0.0, 0.3 + 6 * np.pi))
    assert np.allclose(turned.directions, LaserScan(np.ones(4), -np.pi, np.pi / 2, 5.0, (0.0, 0.0, 0.3)).directions)
