"""The static layer: its map written at the first update only; its walls kept under the LiDAR's."""

from __future__ import annotations

import numpy as np
import pytest

from costmap.grid import FREE_SPACE, INSCRIBED, LETHAL, NO_INFORMATION, GridSpec
from costmap.layer import LayerInputs
from costmap.layers.obstacle import SCAN, ObstacleParams
from costmap.layers.social import PEOPLE
from costmap.mapfile import write_map
from costmap.occupancy import OccupancyGrid
from costmap.plugins import CostmapParams, layered_costmap
from sid.perception.people import Person
from sid.scenario.build import build_costmap
from sid.scenario.lidar import simulate_scan
from sid.scenario.loader import scenario_from_dict

SPEC = GridSpec.from_size(0.05, (-1.0, -4.0), (10.0, 8.0))


def test_the_static_layer_writes_its_map_at_the_first_update_only():
    data = np.zeros(SPEC.shape, dtype=np.int8)
    data[100, :] = 100  # a wall along y = 1.025
    data[:, :10] = -1  # unknown
    params = CostmapParams(obstacle=ObstacleParams(track_unknown_space=True))
    layered = layered_costmap(SPEC, params, static_map=OccupancyGrid(SPEC, data))
    assert list(layered.grids) == ["static", "lidar", "social", "inflation"]
    off_map = simulate_scan((20.0, 0.0, 0.0), [], beams=8)
    with pytest.raises(ValueError, match="outside the costmap"):  # after the static layer reported its map
        layered.update(LayerInputs({SCAN: off_map}))
    assert (layered.master.costs == NO_INFORMATION).all()
    assert layered.update(LayerInputs()) == SPEC.whole  # no scan, nobody: the map alone, still to be written
    master = layered.master.costs
    assert (master[100, 10:] == LETHAL).all() and (master[:90, :10] == NO_INFORMATION).all()
    assert (master[:85, 10:] == FREE_SPACE).all() and master[95, 50] == INSCRIBED
    window = layered.update(LayerInputs({PEOPLE: [Person(1, 4.0, -2.0, 0.0)]}))
    assert window is not None and window != SPEC.whole
    assert (layered.master.costs[100, 10:] == LETHAL).all()
    assert layered.layer("static").update(LayerInputs(), None) is None


def test_static_map_walls_survive_and_lidar_adds_to_them(tmp_path):
    spec = GridSpec(0.05, 0.0, 0.0, 100, 60)
    data = np.zeros(spec.shape, dtype=np.int8)
    data[50, :] = 100  # a wall along y = 2.525 in the static map
    data[56:, :5] = -1  # unknown, behind the static wall as seen from the robot
    write_map(tmp_path / "static.yaml", OccupancyGrid(spec, data))
    scenario = scenario_from_dict(
        {
            "static_map": "static.yaml",
            "obstacles": [{"type": "segment", "points": [[4.0, 0.5], [4.0, 2.0]]}],
            "robot": {"start": [1.0, 1.0], "goal": [4.5, 1.0]},
            "layers": {"obstacle": {"track_unknown_space": True}},
        },
        base_dir=tmp_path,
    )
    layered = build_costmap(scenario, social=False)
    assert list(layered.grids) == ["static", "lidar", "inflation"]
    master = layered.master.costs
    assert (master[50, :] == LETHAL).all()  # static wall, also where the LiDAR saw nothing
    assert (layered.grids["lidar"][10:40, 80] == LETHAL).any()  # the LiDAR-only wall at x = 4.0
    assert (master[56:, :5] == NO_INFORMATION).all()  # unknown in the static map, never seen
    scan = layered.inputs[SCAN]
    assert scan is not None and scan.ranges[np.argmin(np.abs(scan.angles - np.pi / 2))] == pytest.approx(1.5, abs=0.05)
