"""The node's parameters read from real rclpy parameters: the defaults, and the costmap's layer instances named as
Nav2's costmap_2d names them (``costmap.plugins``, ``costmap.NAME.plugin``, ``costmap.NAME.FIELD``), from a
parameters file and from ``-p``."""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
import yaml

from costmap.layer import LayerInputs
from costmap.layers.inflation import InflationParams
from costmap.layers.social import PEOPLE
from costmap.layers.tracked import TRACKS, TrackedPeopleLayer, TrackedPeopleParams
from costmap.plugins import CostmapParams, LayerInstance, layered_costmap
from sid.perception.groups import GroupParams
from sid.ros.params import NODE_NAME, NodeParams, read_params
from sid.tracking import TrackedPerson, Tracks
from sid.tracking.groups import GroupTrackerParams
from sid.tracking.session import TrackingParams
from sid.tracking.tracker import TrackerParams

rclpy = pytest.importorskip("rclpy", reason="rclpy is not installed (pip install 'sid-social[ros]' or source ROS 2)")


@contextmanager
def ros_node(*ros_args: str) -> Iterator:
    """A node named as sid's, in a context of its own started with ``--ros-args ROS_ARGS``."""
    context = rclpy.Context()
    rclpy.init(args=["sid", "--ros-args", *ros_args], context=context)
    node = rclpy.create_node(NODE_NAME, context=context)
    try:
        yield node
    finally:
        node.destroy_node()
        rclpy.shutdown(context=context)


def params_file(folder: Path, costmap: dict) -> Path:
    path = folder / "params.yaml"
    path.write_text(yaml.safe_dump({NODE_NAME: {"ros__parameters": {"costmap": costmap}}}))
    return path


def test_without_parameters_the_node_reads_its_defaults_and_declares_each_layer_parameter() -> None:
    with ros_node() as node:
        params = read_params(node)
        assert params == NodeParams()
        assert params.layers == CostmapParams(plugins=("tracked_people",))
        assert node.get_parameter("costmap.plugins").value == ["tracked_people"]
        assert node.get_parameter("costmap.tracked_people.lookahead").value == TrackedPeopleParams().lookahead
        assert "tracked_people plugin" in node.describe_parameter("costmap.tracked_people.lookahead").description


def test_a_parameters_file_names_two_tracked_people_layers_with_their_own_lookahead(tmp_path: Path) -> None:
    costmap = {
        "plugins": ["tracked_people", "walkers", "inflation"],
        "walkers": {"plugin": "tracked_people", "lookahead": 1.5},
        "inflation": {"inflation_radius": 0.3},
    }
    with ros_node(
        "--params-file", str(params_file(tmp_path, costmap)), "-p", "costmap.tracked_people.lookahead:=0.5"
    ) as node:
        params = read_params(node)
    layers = params.layers
    assert layers.plugins == ("tracked_people", "walkers", "inflation")
    assert layers.instances == {"walkers": LayerInstance("tracked_people", TrackedPeopleParams(1.5))}
    assert layers.layer_params("tracked_people") == TrackedPeopleParams(0.5)
    assert layers.layer_params("inflation") == InflationParams(inflation_radius=0.3)
    layered = layered_costmap(params.grid, layers)
    assert [layer.name for layer in layered.layers] == ["tracked_people", "walkers", "inflation"]
    walker = TrackedPerson(1, 0.0, 0.0, 1.3, 0.0, None, "walking", True, True, 0.0, None, 0.1, 0.0)
    layered.update(LayerInputs({PEOPLE: [walker.as_person()], TRACKS: Tracks([walker])}))
    for name, lookahead in (("tracked_people", 0.5), ("walkers", 1.5)):  # each layer stretches by its own lookahead
        layer = layered.layer(name)
        assert isinstance(layer, TrackedPeopleLayer)
        reach = (0.8 + lookahead * 1.3) * math.sqrt(2 * math.log(200))  # where a walker's cost ends ahead of it
        (inside, beyond) = params.grid.world_to_cell(np.array([[reach - 0.1, 0.0], [reach + 0.1, 0.0]]))
        assert layer.costs[tuple(inside)] > 0 and layer.costs[tuple(beyond)] == 0, name


def test_the_social_parameters_the_tracked_people_layer_draws_with_are_parameters_without_a_social_layer() -> None:
    """The tracked_people layer draws standing people with the social plugin's parameters, but costmap.social.* was
    declared only with a social layer listed: ``-p costmap.social.sigma_front:=3.0`` was ignored in silence."""
    from sid.ros.node import SocialCostmapNode

    rclpy.init(args=["sid", "--ros-args", "-p", "costmap.social.sigma_front:=3.0", "-p", "pose_source:=none"])
    try:
        node = SocialCostmapNode(lambda frame: [], camera_topics=False)
        try:
            assert node.params.layers.plugins == ("tracked_people",)
            assert node.params.layers.social.sigma_front == 3.0
            description = node.node.describe_parameter("costmap.social.sigma_front").description
            assert "the tracked_people layers draw with it" in description
            layer = node.stream.costmap.layer("tracked_people")
            assert isinstance(layer, TrackedPeopleLayer) and layer.social.sigma_front == 3.0
        finally:
            node.node.destroy_node()
    finally:
        rclpy.shutdown()


def test_the_node_builds_its_costmap_from_the_layer_instances() -> None:
    from sid.ros.node import SocialCostmapNode

    args = ["-p", "costmap.plugins:=[walkers, inflation]", "-p", "costmap.walkers.plugin:=tracked_people"]
    rclpy.init(args=["sid", "--ros-args", *args, "-p", "costmap.walkers.lookahead:=2.0", "-p", "pose_source:=none"])
    try:
        node = SocialCostmapNode(lambda frame: [], camera_topics=False)
        try:
            costmap = node.stream.costmap
            assert list(costmap.grids) == ["walkers", "inflation"]
            walkers = costmap.layer("walkers")
            assert isinstance(walkers, TrackedPeopleLayer) and walkers.params == TrackedPeopleParams(2.0)
        finally:
            node.node.destroy_node()
    finally:
        rclpy.shutdown()


@pytest.mark.parametrize(
    ("ros_args", "message"),
    [
        (["-p", "costmap.plugins:=[tracked_people, walkers]"], r"costmap\.walkers\.plugin: required field is missing"),
        (
            ["-p", "costmap.plugins:=[tracked_people, near]", "-p", "costmap.near.plugin:=sonar"],
            'costmap.near.plugin: unknown plugin "sonar"',
        ),
        (["-p", "costmap.plugins:=[tracked_people, tracked_people]"], r"costmap\.plugins: a layer is listed twice"),
        (["-p", "costmap.plugins:=[inflation]"], r"costmap\.plugins: \['inflation'\] has no layer that marks people"),
        (["-p", "costmap.tracked_people.lookahead:=soon"], r"costmap\.tracked_people\.lookahead: expected a finite"),
        (["-p", "costmap.tracked_people.lookahead:=-1.0"], r"costmap\.tracked_people: .*lookahead"),
        (
            ["-p", "costmap.plugins:=[tracked_people, inflation]", "-p", "costmap.inflation.inflation_radius:=50.0"],
            r"costmap\.inflation\.inflation_radius: 50 m is more than the map's diagonal",
        ),
        (["-p", "costmap.plugins:=[lidar, tracked_people]"], "lidar is a lidar layer, which the node cannot feed"),
        (
            ["-p", "costmap.plugins:=[tracked_people, width]", "-p", "costmap.width.plugin:=social"],
            r"costmap\.width is a parameter already",
        ),
    ],
)
def test_a_bad_layer_instance_is_refused_naming_its_parameter(ros_args: list[str], message: str) -> None:
    with ros_node(*ros_args) as node, pytest.raises(ValueError, match=message):
        read_params(node)


@pytest.mark.parametrize(
    ("ros_args", "message"),
    [
        (["-p", "depth_scale:=abc"], r"depth_scale: expected a number, got 'abc'"),
        (["-p", "depth_scale:=[0.001, 0.002]"], r"depth_scale: expected a number, got \[0.001, 0.002\]"),
        (["-p", "camera_height:=true"], r"camera_height: expected a number, got True"),
        (["-p", "global_frame:=5"], r"global_frame: expected a name \(text\), got 5"),
        (["-p", "global_frame:=''"], r"global_frame: a frame id must not be empty"),
        (["-p", "base_frame:=/base_link"], r"base_frame: tf2 frame ids do not start with '/', got '/base_link'"),
        (["-p", "color_topic:=''"], r"color_topic: '' is not a valid topic name \(topic name must not be empty"),
        (["-p", "costmap_topic:=social costmap"], r"costmap_topic: 'social costmap' is not a valid topic name"),
        (["-p", "odom_topic:=/robot//odom"], r"odom_topic: '/robot//odom' is not a valid topic name"),
    ],
)
def test_a_parameter_of_the_wrong_type_or_an_invalid_name_is_refused_naming_it(
    ros_args: list[str], message: str
) -> None:
    with ros_node(*ros_args) as node, pytest.raises(ValueError, match=message):
        read_params(node)


def test_an_integer_for_a_real_parameter_and_a_relative_topic_are_read() -> None:
    with ros_node("-p", "costmap.width:=30", "-p", "costmap_topic:=social_costmap") as node:
        params = read_params(node)
    assert params.costmap__width == 30.0 and isinstance(params.costmap__width, float)
    assert params.costmap_topic == "social_costmap"  # ROS resolves it in the node's namespace


def test_the_group_detector_and_the_trackers_take_their_fields_as_parameters(tmp_path: Path) -> None:
    # As a parameters file names them (sid.scenario.params_file): groups.FIELD, tracking.tracker.FIELD, ...
    path = tmp_path / "params.yaml"
    document = {"groups": {"positions_only_reach": 1.0}, "tracking": {"tracker": {"timeout": 2}, "max_turn_rate": 2.0}}
    path.write_text(yaml.safe_dump({NODE_NAME: {"ros__parameters": document}}))
    with ros_node("--params-file", str(path), "-p", "tracking.groups.walk_distance:=1.2") as node:
        params = read_params(node)
        assert "group tracker" in node.describe_parameter("tracking.groups.walk_distance").description
        assert node.get_parameter("groups.method").value == "ospace"  # every field declared, with its default
    assert params.groups == GroupParams(positions_only_reach=1.0)
    assert params.tracking == TrackingParams(
        tracker=TrackerParams(timeout=2.0), groups=GroupTrackerParams(walk_distance=1.2), max_turn_rate=2.0
    )
    with ros_node() as node:
        assert read_params(node) == NodeParams()


@pytest.mark.parametrize(
    ("ros_args", "message"),
    [
        (["-p", "groups.method:=dbscan"], r"^groups: method must be one of ospace, gcff, rays, paper"),
        (["-p", "groups.alone_price:=0.0"], r"^groups: alone_price must be a finite number of square metres"),
        (
            ["-p", "tracking.tracker.timeout:=soon"],
            r'^tracking\.tracker\.timeout: expected a finite number, got "soon"',
        ),
        (["-p", "tracking.tracker.confirm_hits:=1.5"], r"^tracking\.tracker\.confirm_hits: expected an integer >= 0"),
        (["-p", "tracking.groups.walk_window:=-1.0"], r"^tracking\.groups: walk_window must be a finite number"),
    ],
)
def test_a_bad_group_detector_or_tracker_parameter_is_refused_naming_it(ros_args: list[str], message: str) -> None:
    with ros_node(*ros_args) as node, pytest.raises(ValueError, match=message):
        read_params(node)


def test_the_node_runs_its_trackers_and_group_detector_with_their_parameters() -> None:
    from sid.ros.node import SocialCostmapNode

    args = ["-p", "pose_source:=none", "-p", "tracking.tracker.confirm_hits:=1", "-p", "groups.group_price:=0.5"]
    rclpy.init(args=["sid", "--ros-args", *args])
    try:
        node = SocialCostmapNode(lambda frame: [], camera_topics=False)
        try:
            tracking = node.stream.people.tracking
            assert tracking.people.params.confirm_hits == 1 and tracking.groups.group_params.group_price == 0.5
        finally:
            node.node.destroy_node()
    finally:
        rclpy.shutdown()
