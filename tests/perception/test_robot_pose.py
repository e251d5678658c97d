"""The camera's place on the robot and the map frame: mounts with an offset and a yaw, and the pipeline's output in
the map when a frame carries the robot's pose."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from sid.perception.mount import CameraMount
from sid.perception.people import Person
from sid.perception.pipeline import Pipeline
from sid.perception.robot_pose import RobotPose
from sid.sources.synthetic import SyntheticSource
from sid.synthetic.layouts import layout
from sid.synthetic.noise import DepthNoise, KeypointNoise
from sid.synthetic.pose import TruthPose


def test_default_mount_keeps_the_level_camera_formula() -> None:
    mount = CameraMount(0.9, 0.0)
    points = np.array([[0.5, -0.2, 3.0]])  # camera frame: right, down, forward
    np.testing.assert_allclose(mount.camera_to_world(points), [[3.0, -0.5, 1.1]])


def test_an_offset_and_turned_camera_maps_to_base_footprint_and_back() -> None:
    mount = CameraMount(1.2, 0.3, x=0.25, y=-0.1, yaw=math.pi / 2)
    np.testing.assert_allclose(mount.camera_to_world(np.zeros((1, 3))), [[0.25, -0.1, 1.2]])
    forward = mount.camera_to_world(np.array([[0.0, 0.0, 1.0]]))[0] - mount.position  # the optical axis
    np.testing.assert_allclose(forward, [0.0, math.cos(0.3), -math.sin(0.3)], atol=1e-12)  # left, pitched down
    rng = np.random.default_rng(0)
    points = rng.normal(size=(20, 3))
    np.testing.assert_allclose(mount.world_to_camera(mount.camera_to_world(points)), points)
    np.testing.assert_allclose(mount.rotation.T @ mount.rotation, np.eye(3), atol=1e-12)
    with pytest.raises(ValueError, match="yaw"):
        CameraMount(yaw=math.nan)
    with pytest.raises(ValueError, match="x must be"):
        CameraMount(x=math.inf)


def test_person_to_map_moves_position_facing_and_keypoints() -> None:
    pose = RobotPose(2.0, -1.0, math.pi / 2)
    keypoints = np.array([[1.0, 0.0, 1.5], [np.nan, np.nan, np.nan]])
    moved = pose.person_to_map(Person(4, 1.0, 0.5, math.pi, 0.8, keypoints))
    assert (moved.id, moved.x, moved.y, moved.orientation_quality) == (4, pytest.approx(1.5), pytest.approx(0.0), 0.8)
    assert moved.theta == pytest.approx(-math.pi / 2)
    np.testing.assert_allclose(moved.keypoints_world[0], [2.0, 0.0, 1.5])
    assert np.isnan(moved.keypoints_world[1]).all()
    assert pose.person_to_map(Person(5, 0.0, 0.0)).theta is None


def _exact(scene: object) -> SyntheticSource:
    return SyntheticSource(scene, frames=1, noise=DepthNoise.exact(), keypoint_noise=KeypointNoise(0.0, 0.0))


def test_pipeline_reports_in_the_map_when_the_robot_pose_is_known() -> None:
    frame = _exact("S3")[0]
    pipeline = Pipeline(TruthPose())
    base = pipeline(frame)
    assert base.frame_id == "base_footprint" and base.robot_pose is None and len(base.groups) == 1
    pose = RobotPose(3.0, -2.0, 2.5)
    found = pipeline(dataclasses.replace(frame, robot_pose=pose))
    assert found.frame_id == "map" and found.robot_pose == pose
    for in_base, in_map in zip(base.people, found.people, strict=True):
        np.testing.assert_allclose(in_map.position, pose.to_map(in_base.position)[0])
        assert in_base.theta is not None and in_map.theta == pytest.approx(pose.yaw_to_map(in_base.theta))
        assert in_base.keypoints_world is not None and in_map.keypoints_world is not None
        np.testing.assert_allclose(in_map.keypoints_world[:, :2], pose.to_map(in_base.keypoints_world[:, :2]))
        np.testing.assert_array_equal(in_map.keypoints_world[:, 2], in_base.keypoints_world[:, 2])
    (group_base,), (group_map,) = base.groups, found.groups
    assert group_map.members == group_base.members and group_map.area == pytest.approx(group_base.area, abs=1e-9)
    np.testing.assert_allclose(group_map.interest_point, pose.to_map(np.array(group_base.interest_point))[0])
    np.testing.assert_allclose(_rows(group_map.zone), _rows(pose.to_map(group_base.zone)), atol=1e-9)
    record = found.to_json()
    assert record["frame_id"] == "map" and record["robot_pose"] == {"x": 3.0, "y": -2.0, "yaw": 2.5}
    assert base.to_json(keypoints=False)["frame_id"] == "base_footprint" and base.to_json()["robot_pose"] is None


def _rows(points: np.ndarray) -> np.ndarray:
    """The rows of a (K, 2) array in lexicographic order (polygons compared whatever their first vertex)."""
    return points[np.lexsort(points.T[::-1])]


def test_a_turned_offset_camera_sees_people_where_they_stand_on_the_robot() -> None:
    mount = CameraMount(1.0, 0.1, x=0.3, y=-0.2, yaw=0.2)
    scene = dataclasses.replace(layout("S2"), mount=mount)
    frame = _exact(scene)[0]
    found = Pipeline(TruthPose(), mount)(frame)
    assert len(found.people) == 3
    for person in found.people:
        true = min(frame.truth.people, key=lambda t: math.hypot(person.x - t.x, person.y - t.y))
        assert math.hypot(person.x - true.x, person.y - true.y) < 0.05
        assert person.theta is not None and abs(math.remainder(person.theta - true.theta, math.tau)) < 0.15


@pytest.mark.parametrize(("robot_yaw", "heading"), [(0.0, -math.pi), (-math.pi / 2, -math.pi / 2), (math.pi, 0.0)])
def test_yaw_to_map_keeps_its_range_minus_pi_open(robot_yaw, heading) -> None:
    """math.remainder gives -pi for an odd multiple of pi, outside the promised (-pi, pi]: it is pi now."""
    assert RobotPose(0.0, 0.0, robot_yaw).yaw_to_map(heading) == math.pi
