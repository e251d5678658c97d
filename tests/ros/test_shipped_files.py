"""The parameters YAML, the Nav2 example and the launch file sid ships with ``sid ros``."""

from __future__ import annotations

import ast

import pytest
import yaml

from sid.cli.ros import SHARE
from sid.perception.mount import CameraMount
from sid.ros.params import NODE_NAME, PARAMETERS, NodeParams


def flatten(tree: dict, prefix: str = "") -> dict:
    out = {}
    for key, value in tree.items():
        if isinstance(value, dict):
            out |= flatten(value, f"{prefix}{key}.")
        else:
            out[f"{prefix}{key}"] = value
    return out


def test_parameters_yaml_lists_every_parameter_with_its_default() -> None:
    document = yaml.safe_load((SHARE / "sid_params.yaml").read_text())
    shipped = flatten(document[NODE_NAME]["ros__parameters"])
    assert shipped == {name: default for name, default, _ in PARAMETERS}
    assert all(description for _, _, description in PARAMETERS)
    assert NodeParams().grid.shape == (400, 400)


def test_the_camera_mount_parameters_place_the_camera_on_the_base() -> None:
    mount = NodeParams(camera_x=0.25, camera_y=-0.05, camera_height=1.1, camera_tilt=0.2, camera_yaw=0.3).mount
    assert mount == CameraMount(height=1.1, tilt=0.2, x=0.25, y=-0.05, yaw=0.3)
    with pytest.raises(ValueError, match="yaw"):
        NodeParams(camera_yaw=float("nan"))


def test_nav2_example_puts_the_keepout_filter_in_both_costmaps() -> None:
    document = yaml.safe_load((SHARE / "nav2_social_costmap.yaml").read_text())
    for costmap in ("global_costmap", "local_costmap"):
        params = document[costmap][costmap]["ros__parameters"]
        assert params["filters"] == ["social_filter"]
        assert params["social_filter"]["plugin"] == "nav2_costmap_2d::KeepoutFilter"
        assert params["social_filter"]["filter_info_topic"] == "/social_costmap_filter_info"
    server = document["costmap_filter_info_server"]["ros__parameters"]
    assert (server["type"], server["mask_topic"], server["base"], server["multiplier"]) == (
        0,
        "/social_costmap",
        0.0,
        1.0,
    )


def test_launch_file_runs_sid_ros_with_the_shipped_parameters() -> None:
    source = (SHARE / "sid.launch.py").read_text()
    tree = ast.parse(source)  # valid Python; `launch` itself is not installed here
    assert any(isinstance(n, ast.FunctionDef) and n.name == "generate_launch_description" for n in tree.body)
    assert '"sid_params.yaml"' in source and '"--params-file"' in source
