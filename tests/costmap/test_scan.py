"""The LaserScan record: a pose that is not finite is refused."""

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
