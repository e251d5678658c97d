"""The node's own behaviour, in process with real rclpy (no DDS peer needed): what it says about its pose source."""

from __future__ import annotations

import pytest

rclpy = pytest.importorskip("rclpy", reason="rclpy is not installed (pip install 'sid-social[ros]' or source ROS 2)")


def test_odometry_in_another_frame_than_the_costmap_is_warned_of_once(capfd: pytest.CaptureFixture[str]) -> None:
    """/odom is in ``odom`` on most robots, and the mask in ``map`` by default: with pose_source odom the node takes
    the odometry pose as the pose in global_frame, so it must say so (once) rather than place the mask off by the
    map -> odom drift in silence. A frame without a pose names the odometry topic it waits for."""
    from nav_msgs.msg import Odometry

    from sid.ros.node import SocialCostmapNode
    from sid.sources.synthetic import SyntheticSource

    rclpy.init(args=["sid", "--ros-args", "-p", "pose_source:=odom", "-p", "odom_topic:=/robot/odom"])
    try:
        node = SocialCostmapNode(lambda frame: [], camera_topics=False)
        try:
            node.on_frame(SyntheticSource("S4", frames=1)[0])
            odometry = Odometry()
            odometry.header.frame_id, odometry.child_frame_id = "odom", "base_footprint"
            for _ in range(3):
                node._on_odometry(odometry)
        finally:
            node.node.destroy_node()
    finally:
        rclpy.shutdown()
    err = capfd.readouterr().err
    assert "frame 0: skipped, no robot pose yet (odometry on /robot/odom)" in err
    warning = "odometry on /robot/odom is in frame 'odom', not global_frame 'map'"
    assert err.count(warning) == 1 and "-p global_frame:=odom" in err


def test_tracks_started_afresh_when_the_robot_pose_arrives_get_new_ids() -> None:
    """pose_source auto: frames without a pose are placed with the robot at the origin until the first pose arrives;
    tracking then starts afresh. The node built a new stream there, so track ids began again at 1 and a listener
    took the new tracks for the old ones. The ids now keep counting up."""
    from dataclasses import replace

    from nav_msgs.msg import Odometry

    from sid.ros.node import SocialCostmapNode
    from sid.sources.synthetic import SyntheticSource
    from sid.synthetic.pose import TruthPose

    rclpy.init(args=["sid", "--ros-args", "-p", "pose_source:=auto"])
    try:
        node = SocialCostmapNode(TruthPose(), camera_topics=False)
        try:
            frames = [replace(frame, robot_pose=None) for frame in SyntheticSource("S4", frames=10)]

            def ids(frame: object) -> set[int]:
                pose = node.frame_pose(frame, None)
                return {person.id for person in node.stream.update(frame, pose).people}

            before = set().union(*(ids(frame) for frame in frames[:5]))
            assert node.fixed_robot and len(before) == 4
            odometry = Odometry()
            odometry.header.frame_id = "map"
            node._on_odometry(odometry)
            after = set().union(*(ids(frame) for frame in frames[5:]))
            assert not node.fixed_robot and len(after) == 4
        finally:
            node.node.destroy_node()
    finally:
        rclpy.shutdown()
    assert after.isdisjoint(before) and min(after) > max(before)
