"""The plugin list names, orders and checks the layers; layer instances as in Nav2, each with a name, a plugin and its
own parameters (two LiDAR layers in one costmap); a scenario file's layers."""

from __future__ import annotations

import numpy as np
import pytest

from costmap.grid import FREE_SPACE, LETHAL, NO_INFORMATION, GridSpec
from costmap.layer import LayerInputs
from costmap.layered import LayeredCostmap
from costmap.layers.inflation import InflationLayer, InflationParams
from costmap.layers.obstacle import SCAN, ObstacleLayer, ObstacleParams
from costmap.mapfile import write_map
from costmap.occupancy import OccupancyGrid
from costmap.plugins import PLUGINS, CostmapParams, LayerInstance, layered_costmap
from costmap.scan import LaserScan
from sid.scenario.build import build_costmap
from sid.scenario.loader import ScenarioError, scenario_from_dict
from tests.costmap.scenes import Unknown

SPEC = GridSpec.from_size(0.05, (-1.0, -5.0), (12.0, 10.0))
NEAR = ObstacleParams(obstacle_max_range=3.0, raytrace_max_range=3.0)


def _scan() -> LaserScan:
    """Two returns straight ahead of a sensor at the origin: one at 2 m (beam 0), one at 6 m (beam 1, 0.1 rad left)."""
    return LaserScan(np.array([2.0, 6.0]), 0.0, 0.1, 8.0, (0.0, 0.0, 0.0))


def _lethal_at(layered, name: str, x: float, y: float) -> bool:
    (row, col) = SPEC.world_to_cell(np.array([x, y]))[0]
    return bool(layered.grids[name][row, col] == LETHAL)


def test_two_lidar_layers_with_their_own_parameters_in_one_costmap() -> None:
    params = CostmapParams(
        plugins=("near_lidar", "lidar", "inflation"), instances={"near_lidar": LayerInstance("lidar", NEAR)}
    )
    layered = layered_costmap(SPEC, params)
    assert [layer.name for layer in layered.layers] == ["near_lidar", "lidar", "inflation"]
    near, far = layered.layer("near_lidar"), layered.layer("lidar")
    assert isinstance(near, ObstacleLayer) and isinstance(far, ObstacleLayer)
    assert near.params == NEAR and far.params == params.obstacle  # a plugin's own name: the costmap's section
    layered.update(LayerInputs({SCAN: _scan()}))
    far_hit = (6.0 * np.cos(0.1), 6.0 * np.sin(0.1))
    assert _lethal_at(layered, "near_lidar", 2.0, 0.0) and not _lethal_at(layered, "near_lidar", *far_hit)
    assert _lethal_at(layered, "lidar", 2.0, 0.0) and _lethal_at(layered, "lidar", *far_hit)
    assert params.named("lidar") == ["near_lidar", "lidar"] and params.plugin("near_lidar") == "lidar"


def test_an_instance_of_an_unknown_plugin_is_refused() -> None:
    params = CostmapParams(plugins=("lidar", "sonar_1"), instances={"sonar_1": LayerInstance("sonar")})
    with pytest.raises(ValueError, match="unknown layer 'sonar'"):
        layered_costmap(SPEC, params)
    with pytest.raises(ValueError, match="must be a LayerInstance"):
        CostmapParams(instances={"near": "lidar"})  # type: ignore[dict-item]


def _scenario(layers: dict) -> dict:
    return {
        "map": {"resolution": 0.05, "origin": [-1, -5], "size": [12, 10]},
        "robot": {"start": [0, 0, 0], "goal": [5, 0, 0]},
        "layers": layers,
    }


def test_a_scenario_file_declares_named_layers_as_nav2_does() -> None:
    layers = {
        "plugins": ["static", "near_lidar", "lidar", "social", "inflation"],
        "near_lidar": {"plugin": "lidar", "obstacle_max_range": 3.0, "raytrace_max_range": 3.0},
        "obstacle": {"obstacle_max_range": 8.0},
    }
    params = scenario_from_dict(_scenario(layers)).layers
    assert params.layer_params("near_lidar") == NEAR
    assert params.layer_params("lidar") == ObstacleParams(obstacle_max_range=8.0)
    assert params.named("lidar") == ["near_lidar", "lidar"]
    only_near = {"plugins": ["near_lidar", "inflation"], "near_lidar": {"plugin": "lidar"}}
    assert scenario_from_dict(_scenario(only_near)).layers.layer_params("near_lidar") == ObstacleParams()


@pytest.mark.parametrize(
    ("layers", "message"),
    [
        ({"plugins": ["lidar", "near"]}, r"layers.plugins\[1\]: unknown layer \"near\""),
        ({"plugins": ["lidar"], "near": {"plugin": "lidar"}}, "layers.near: unknown field"),
        ({"plugins": ["near", "inflation"], "near": {"obstacle_max_range": 2}}, "layers.near.plugin: required"),
        ({"plugins": ["near"], "near": {"plugin": "sonar"}}, 'layers.near.plugin: unknown plugin "sonar"'),
        ({"plugins": ["lidar", "near"], "near": {"plugin": "lidar", "sigma": 1}}, "layers.near.sigma: unknown"),
        ({"plugins": ["near", "inflation"], "near": {"plugin": "inflation"}}, "has no layer that marks people"),
        ({"plugins": ["lidar", "map"], "map": {"plugin": "static", "x": 1}}, "static plugin takes no parameters"),
        (
            {"plugins": ["lidar", "wide"], "wide": {"plugin": "inflation", "inflation_radius": 50}},
            "layers.wide.inflation_radius: 50 m is more than the map's diagonal",
        ),
    ],
)
def test_bad_layer_instances_are_named(layers: dict, message: str) -> None:
    with pytest.raises(ScenarioError, match=message):
        scenario_from_dict(_scenario(layers))


def test_the_plugin_list_names_orders_and_checks_the_layers():
    layered = layered_costmap(SPEC)
    assert [layer.name for layer in layered.layers] == ["lidar", "social", "inflation"]  # no static map, no static
    assert isinstance(layered.layer("lidar"), ObstacleLayer) and layered.layer("static") is None
    assert layered.layer("lidar").people_clear_radius == pytest.approx(0.2 + 0.1)
    baseline = layered_costmap(SPEC, CostmapParams().without("social"), body_radius=0.3)
    assert baseline.layer("lidar").people_clear_radius == 0.0  # nobody draws the people: their marks stay
    assert layered_costmap(SPEC, CostmapParams(), body_radius=0.3).layer("lidar").people_clear_radius == 0.4
    renamed = layered_costmap(
        SPEC, CostmapParams(plugins=("lidar", "rear", "inflation")), plugins={**PLUGINS, "rear": PLUGINS["lidar"]}
    )
    assert list(renamed.grids) == ["lidar", "rear", "inflation"]
    with pytest.raises(ValueError, match="unknown layer 'sonar'"):
        layered_costmap(SPEC, CostmapParams(plugins=("lidar", "sonar")))
    with pytest.raises(ValueError, match="listed twice"):
        CostmapParams(plugins=("lidar", "lidar"))
    with pytest.raises(ValueError, match="distinct names"):
        LayeredCostmap(SPEC, [ObstacleLayer(SPEC), ObstacleLayer(SPEC)])
    with pytest.raises(ValueError, match="differs from the costmap"):
        LayeredCostmap(SPEC, [InflationLayer(GridSpec(0.1, 0.0, 0.0, 10, 10), InflationParams(), 0.25)])
    with pytest.raises(ValueError, match="combination method"):
        Unknown(SPEC, "min")


def test_a_scenario_names_its_layers_in_order(tmp_path):
    data = {
        "map": {"resolution": 0.05, "origin": [0.0, 0.0], "size": [4.0, 3.0]},
        "people": [{"id": 1, "x": 2.0, "y": 1.5}],
        "robot": {"start": [0.5, 1.5], "goal": [3.5, 1.5]},
        "layers": {"plugins": ["lidar", "inflation"]},
    }
    layered = build_costmap(scenario_from_dict(data, base_dir=tmp_path))
    assert list(layered.grids) == ["lidar", "inflation"]
    assert layered.master.cost_at([[2.0, 2.3]])[0] == FREE_SPACE  # no personal space: the person is a LiDAR mark
    for plugins, message in (
        (["lidar", "sonar"], r'layers\.plugins\[1\]: unknown layer "sonar"'),
        (["lidar", "lidar"], r"layers\.plugins: a layer is listed twice"),
        ("lidar", r"layers\.plugins: expected a list of layer names"),
        ([], r"layers\.plugins: \[\] has no layer that marks people; list one of lidar, social, tracked_people"),
        (["static", "inflation"], r"layers\.plugins: \['static', 'inflation'\] has no layer that marks people"),
    ):
        with pytest.raises(ScenarioError, match=message):
            scenario_from_dict({**data, "layers": {"plugins": plugins}}, base_dir=tmp_path)


def test_a_scenarios_tracked_people_layer_draws_its_people_as_the_social_layer_does(tmp_path) -> None:
    """With tracked_people the only people layer, sid plan's costmap was empty: nothing fed it tracks, and a path
    went between two people in conversation, 0.4 m from each (a probe, 7 December 2026)."""
    data = {
        "map": {"resolution": 0.05, "origin": [0.0, 0.0], "size": [12.0, 8.0]},
        "people": [{"id": 1, "x": 6.0, "y": 4.4, "theta": -1.57}, {"id": 2, "x": 6.0, "y": 3.6, "theta": 1.57}],
        "robot": {"start": [1.0, 4.0], "goal": [11.0, 4.0]},
    }
    drawn = {
        plugins: build_costmap(scenario_from_dict({**data, "layers": {"plugins": list(plugins)}}, base_dir=tmp_path))
        for plugins in (("tracked_people", "inflation"), ("social", "inflation"))
    }
    tracked, social = (drawn[k].master.costs for k in drawn)
    assert tracked[int(4.0 / 0.05), int(6.0 / 0.05)] >= 253  # between the two: their o-space
    np.testing.assert_array_equal(tracked, social)
    without = build_costmap(
        scenario_from_dict({**data, "layers": {"plugins": ["tracked_people"]}}, base_dir=tmp_path), social=False
    )
    assert not without.master.costs.any()  # a robot without recognition: no tracks


def test_unknown_space_and_the_peoples_clearing_come_from_the_listed_layer_instances(tmp_path) -> None:
    data = _scenario(
        {
            "plugins": ["static", "near", "crowd", "inflation"],
            "near": {"plugin": "lidar", "track_unknown_space": True},
            "crowd": {"plugin": "social", "people_clear_margin": 0.5},
        }
    )
    write_map(tmp_path / "map.yaml", OccupancyGrid(SPEC, np.full(SPEC.shape, -1, np.int8)))  # all unknown
    layered = build_costmap(scenario_from_dict({**data, "static_map": "map.yaml"}, base_dir=tmp_path))
    assert layered.default_value == NO_INFORMATION  # the listed LiDAR layer tracks unknown space, not the section
    assert (layered.grids["static"] == NO_INFORMATION).all()
    assert (layered.master.costs == NO_INFORMATION).any()
    assert layered.layer("near").people_clear_radius == pytest.approx(0.2 + 0.5)  # the listed social layer's margin
    near = LayerInstance("lidar", ObstacleParams(track_unknown_space=True))
    with pytest.raises(ValueError, match=r"plugins: the lidar layers disagree on track_unknown_space \(near True, li"):
        CostmapParams(plugins=("near", "lidar"), instances={"near": near})
    disagreeing = {**data["layers"], "plugins": ["near", "lidar", "crowd"]}
    with pytest.raises(ScenarioError, match=r"layers\.plugins: the lidar layers disagree on track_unknown_space"):
        scenario_from_dict({**data, "layers": disagreeing})


@pytest.mark.parametrize(
    ("instance", "message"),
    [
        (
            LayerInstance("lidar", {"obstacle_max_range": 5.0}),
            r"near's params must be ObstacleParams or None for the lidar plugin, got dict",
        ),
        (
            LayerInstance("inflation", NEAR),
            r"near's params must be InflationParams or None for the inflation plugin, got Obs",
        ),
        (LayerInstance("static", NEAR), r"near's params must be None \(it takes no parameters\) for the static plugin"),
    ],
)
def test_an_instance_with_parameters_of_another_plugin_is_named(instance: LayerInstance, message: str) -> None:
    with pytest.raises(ValueError, match=rf"instances: {message}"):
        CostmapParams(plugins=("near", "social"), instances={"near": instance})


def test_an_instance_of_a_plugin_of_the_callers_own_takes_any_params() -> None:
    custom = CostmapParams(plugins=("sonar_1", "lidar"), instances={"sonar_1": LayerInstance("sonar", {"range": 3.0})})
    assert custom.layer_params("sonar_1") == {"range": 3.0}
