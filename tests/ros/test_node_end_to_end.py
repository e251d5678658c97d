"""``sid ros`` end to end over real ROS 2 topics: the node runs in its own process (``python -m sid ros``), this
test publishes a synthetic realsense2_camera (colour, aligned depth, camera_info) and odometry, and subscribes to
what the node publishes: the KeepoutFilter mask, the markers and the groups. A second test runs
``sid ros --source synthetic:S4`` with every parameter at its default: no pose arrives, the robot is fixed.

The scene is layout S4 (four people in a conversation, 1.9 m ahead of the camera), rendered once at 640x360 with
exact depth. The pose model is a crafted YOLO-pose ONNX model that answers the scene's true keypoints (the scene
is static), so the node runs its real model path: onnxruntime, letterbox, lifting, trackers, costmap.
"""

from __future__ import annotations

import array
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from costmap.export import filter_mask_cost
from sid.perception.camera import Calibration
from sid.perception.pose.base import Letterbox
from sid.sources.synthetic import SyntheticSource
from sid.synthetic.noise import DepthNoise, KeypointNoise
from sid.synthetic.pose import TruthPose
from sid.synthetic.sensor import D435I_COLOR
from tests.conftest import REPO_ROOT

rclpy = pytest.importorskip("rclpy", reason="rclpy is not installed (pip install 'sid-social[ros]' or source ROS 2)")
from nav_msgs.msg import OccupancyGrid, Odometry  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy  # noqa: E402
from sensor_msgs.msg import CameraInfo, Image  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from visualization_msgs.msg import MarkerArray  # noqa: E402

from tests.pose_models import build_yolo_pose_model  # noqa: E402

ROBOT = (1.0, 2.0, 0.5)  # the robot's pose in the map (x, y, yaw), sent as odometry
FORMATION_DISTANCE = 1.9  # S4's formation centre, metres ahead of the camera
RATE_HZ = 5.0
WANTED = 25  # costmaps to collect once the group shows
BAD_FRAME_LOGGED = "skipped, colour image encoding 'yuv422' is not supported"


def render_scene():
    calibration = Calibration(D435I_COLOR.scaled(640, 360))
    source = SyntheticSource(
        "S4", frames=1, seed=0, noise=DepthNoise.exact(), keypoint_noise=KeypointNoise(0, 0), calibration=calibration
    )
    frame = source[0]
    return frame, TruthPose()(frame)


def crafted_model(path: Path, frame, detections) -> Path:
    """A YOLO-pose model (256x256 input) whose output is the scene's keypoints in its letterboxed input pixels."""
    box = Letterbox.fit(frame.color.shape[:2], (256, 256))
    columns = []
    for d in detections:
        corners = box.to_input(d.box.reshape(2, 2))
        (x0, y0), (x1, y1) = corners
        keypoints = box.to_input(d.keypoints)
        column = [(x0 + x1) / 2, (y0 + y1) / 2, x1 - x0, y1 - y0, 0.9]
        column += np.column_stack([keypoints, d.scores]).ravel().tolist()
        columns.append(column)
    return build_yolo_pose_model(path, np.array(columns, dtype=np.float32).T)


def stamp(seconds: float):
    from builtin_interfaces.msg import Time

    sec = math.floor(seconds)
    return Time(sec=sec, nanosec=int((seconds - sec) * 1e9))


def image(pixels: np.ndarray, encoding: str, when) -> Image:
    msg = Image(height=pixels.shape[0], width=pixels.shape[1], encoding=encoding, step=pixels.strides[0])
    msg.header.stamp, msg.header.frame_id = when, "camera_color_optical_frame"
    msg.data = array.array("B", np.ascontiguousarray(pixels).tobytes())
    return msg


def camera_info(frame, when) -> CameraInfo:
    c = frame.calibration.color
    msg = CameraInfo(width=c.width, height=c.height, distortion_model="plumb_bob", d=[0.0] * 5)
    msg.k = [c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0]
    msg.header.stamp = when
    return msg


def odometry(when) -> Odometry:
    msg = Odometry()
    msg.header.stamp, msg.header.frame_id, msg.child_frame_id = when, "map", "base_footprint"
    x, y, yaw = ROBOT
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
    msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return msg


@pytest.mark.slow
def test_node_publishes_the_group_zone_for_nav2(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    frame, detections = render_scene()
    assert len(detections) == 4
    model = crafted_model(tmp_path / "pose.onnx", frame, detections)
    domain = 100 + os.getpid() % 100  # this test's own DDS domain, away from anything else on the machine
    env = os.environ | {"ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    node_log = (tmp_path / "node.log").open("w")
    command = [sys.executable, "-m", "sid", "ros", "--model", str(model), "--ros-args", "-p", "pose_source:=odom"]
    node_process = subprocess.Popen(command, cwd=REPO_ROOT, env=env, stdout=node_log, stderr=subprocess.STDOUT)

    context = rclpy.Context()
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    rclpy.init(context=context, domain_id=domain)
    test_node = rclpy.create_node("sid_test_camera", context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(test_node)
    grids: list[tuple[float, OccupancyGrid]] = []
    markers: list[MarkerArray] = []
    groups: list[dict] = []
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    test_node.create_subscription(OccupancyGrid, "/social_costmap", lambda m: grids.append((time.time(), m)), latched)
    test_node.create_subscription(MarkerArray, "/social_markers", markers.append, 10)
    test_node.create_subscription(String, "/social_groups", lambda m: groups.append(json.loads(m.data)), 10)
    publishers = {
        "color": test_node.create_publisher(Image, "/camera/camera/color/image_raw", 5),
        "depth": test_node.create_publisher(Image, "/camera/camera/aligned_depth_to_color/image_raw", 5),
        "info": test_node.create_publisher(CameraInfo, "/camera/camera/color/camera_info", 5),
        "odom": test_node.create_publisher(Odometry, "/odom", 10),
    }
    depth_mm = np.round(frame.depth * 1000).astype(np.uint16)
    try:
        deadline = time.monotonic() + 180
        sent = 0
        skip_logged = False
        answered_before_skip = 0  # group messages received before the node had logged a bad frame
        while time.monotonic() < deadline and node_process.poll() is None:
            if not skip_logged and BAD_FRAME_LOGGED in (tmp_path / "node.log").read_text():
                skip_logged, answered_before_skip = True, len(groups)
            if (
                skip_logged
                and sum(1 for g in groups if g["groups"]) >= WANTED
                and len(groups) > answered_before_skip + 3
            ):
                break
            when = stamp(time.time())
            publishers["odom"].publish(odometry(when))
            publishers["info"].publish(camera_info(frame, when))
            # Once it has answered a frame (so its image subscriptions are matched: the latched costmap can come
            # sooner), every third frame one it cannot read, until it has logged one (the camera topics are best
            # effort, so on a loaded machine a single bad frame may never arrive): it must log it and go on.
            sent += 1
            bad = bool(groups) and not skip_logged and sent % 3 == 0
            publishers["color"].publish(image(frame.color, "yuv422" if bad else "rgb8", when))
            publishers["depth"].publish(image(depth_mm, "16UC1", when))
            next_frame = time.monotonic() + 1 / RATE_HZ
            while time.monotonic() < next_frame:
                executor.spin_once(timeout_sec=0.02)
    finally:
        node_process.terminate()
        node_process.wait(timeout=30)
        node_log.close()
        executor.shutdown()
        test_node.destroy_node()
        rclpy.shutdown(context=context)
    log = (tmp_path / "node.log").read_text()
    assert sum(1 for g in groups if g["groups"]) >= WANTED, f"too few costmaps with a group; node log:\n{log[-3000:]}"
    assert BAD_FRAME_LOGGED in log
    assert len(groups) > answered_before_skip + 3, "the node stopped answering after a bad frame"

    # The group: four tracked people around one conversation, in the map frame (the odometry pose applied).
    last = groups[-1]
    assert last["frame_id"] == "map" and len(last["people"]) == 4
    (group,) = last["groups"]
    assert group["kind"] == "conversation" and len(group["members"]) == 4
    x, y, yaw = ROBOT
    centre = np.array([x + FORMATION_DISTANCE * math.cos(yaw), y + FORMATION_DISTANCE * math.sin(yaw)])
    assert np.linalg.norm(np.array(group["interest_point"]) - centre) < 0.15

    # The mask: in the map frame, the group zone high for Nav2's KeepoutFilter, free far from everyone.
    _, grid = grids[-1]
    assert grid.header.frame_id == "map" and (grid.info.width, grid.info.height) == (400, 400)
    assert grid.info.resolution == pytest.approx(0.05) and grid.info.origin.position.x == pytest.approx(-10.0)
    data = np.array(grid.data, dtype=np.int8).reshape(grid.info.height, grid.info.width)
    costs = filter_mask_cost(data)
    row, col = (int((centre[1] + 10.0) / 0.05), int((centre[0] + 10.0) / 0.05))
    assert costs[row, col] >= 230  # the group zone (240), as the filter reads it
    assert costs[int((y + 10.0) / 0.05), int((x + 10.0) / 0.05)] == 0  # where the robot stands
    assert costs.max() == 254  # the bodies

    # RViz markers: a fresh array per frame (DELETEALL first) with the people and the group's zone.
    namespaces = {m.ns for m in markers[-1].markers}
    assert {"people", "facing", "group_zones", "group_ids"} <= namespaces
    assert sum(1 for m in markers[-1].markers if m.ns == "people") == 4

    # Latency from the image's stamp (set when published) to the costmap's arrival here; median over the frames.
    latencies = [received - (g.header.stamp.sec + g.header.stamp.nanosec * 1e-9) for received, g in grids[-WANTED:]]
    median_ms = 1000 * float(np.median(latencies))
    print(f"\nsid ros: image publish -> costmap received, median {median_ms:.1f} ms over {len(latencies)} frames")


@pytest.mark.slow
def test_a_source_without_a_robot_pose_publishes_with_default_parameters(tmp_path: Path) -> None:
    domain = 100 + (os.getpid() + 50) % 100
    env = os.environ | {"ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    log_path = tmp_path / "node.log"
    with log_path.open("w") as node_log:
        node_process = subprocess.Popen(
            [sys.executable, "-m", "sid", "ros", "--source", "synthetic:S4"],
            cwd=REPO_ROOT,
            env=env,
            stdout=node_log,
            stderr=subprocess.STDOUT,
        )
        context = rclpy.Context()
        rclpy.init(context=context, domain_id=domain)
        test_node = rclpy.create_node("sid_test_listener", context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(test_node)
        grids: list[OccupancyGrid] = []
        groups: list[dict] = []
        latched = QoSProfile(
            depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
        )
        test_node.create_subscription(OccupancyGrid, "/social_costmap", grids.append, latched)
        test_node.create_subscription(String, "/social_groups", lambda m: groups.append(json.loads(m.data)), 10)
        try:
            deadline = time.monotonic() + 180  # a hang bound, not a speed check
            while time.monotonic() < deadline and node_process.poll() is None:
                executor.spin_once(timeout_sec=0.05)
                if sum(1 for g in groups if g["groups"]) >= 5 and grids:
                    break
        finally:
            node_process.terminate()
            node_process.wait(timeout=30)
            executor.shutdown()
            test_node.destroy_node()
            rclpy.shutdown(context=context)
    log = log_path.read_text()
    assert sum(1 for g in groups if g["groups"]) >= 5 and grids, f"no group published; node log:\n{log[-3000:]}"
    # One warning, saying how to choose: the robot is fixed at the map's origin, the camera looking along +x.
    assert log.count("pose_source:=none") == 1 and "skipped, no robot pose" not in log, log[-3000:]
    last = groups[-1]
    assert last["frame_id"] == "map" and len(last["groups"][0]["members"]) == 4
    assert np.linalg.norm(np.array(last["groups"][0]["interest_point"]) - [FORMATION_DISTANCE, 0.0]) < 0.15
    grid = grids[-1]
    costs = filter_mask_cost(np.array(grid.data, dtype=np.int8).reshape(grid.info.height, grid.info.width))
    row, col = int((0.0 + 10.0) / 0.05), int((FORMATION_DISTANCE + 10.0) / 0.05)
    assert costs[row, col] >= 230 and costs[200, 200] == 0  # the group zone; the robot's own cell free


@pytest.mark.slow
def test_silent_camera_topics_are_reported_with_the_reason(tmp_path: Path) -> None:
    """realsense2_camera started without ``align_depth.enable:=true`` publishes no aligned depth, and a camera whose
    colour comes only compressed publishes no raw Image: the node must say, per topic, that nothing arrives and why
    (no publisher, or a publisher of another type), and must not log one line per colour image meanwhile."""
    from sensor_msgs.msg import CompressedImage

    model = build_yolo_pose_model(tmp_path / "pose.onnx", np.zeros((56, 10), dtype=np.float32))
    domain = 100 + (os.getpid() + 25) % 100
    env = os.environ | {"ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    log_path = tmp_path / "node.log"
    command = [sys.executable, "-m", "sid", "ros", "--model", str(model), "--ros-args", "-p", "pose_source:=none"]
    with log_path.open("w") as node_log:
        node_process = subprocess.Popen(command, cwd=REPO_ROOT, env=env, stdout=node_log, stderr=subprocess.STDOUT)
        context = rclpy.Context()
        rclpy.init(context=context, domain_id=domain)
        test_node = rclpy.create_node("sid_test_camera", context=context)
        colour = test_node.create_publisher(Image, "/camera/camera/color/image_raw", 5)
        depth = test_node.create_publisher(CompressedImage, "/camera/camera/aligned_depth_to_color/image_raw", 5)
        info = test_node.create_publisher(CameraInfo, "/camera/camera/color/camera_info", 5)
        pixels = np.zeros((48, 64, 3), dtype=np.uint8)
        try:
            start = time.monotonic()
            while time.monotonic() < start + 25 and node_process.poll() is None:
                when = stamp(time.time())
                colour.publish(image(pixels, "rgb8", when))
                depth.publish(CompressedImage(format="16UC1; compressedDepth png"))
                message = CameraInfo(width=64, height=48, k=[50.0, 0.0, 32.0, 0.0, 50.0, 24.0, 0.0, 0.0, 1.0])
                message.header.stamp = when
                info.publish(message)
                time.sleep(1 / 30)
                if "nothing arrived on /camera/camera/aligned" in log_path.read_text():
                    break
        finally:
            node_process.terminate()
            node_process.wait(timeout=30)
            test_node.destroy_node()
            rclpy.shutdown(context=context)
    log = log_path.read_text()
    assert (
        "nothing arrived on /camera/camera/aligned_depth_to_color/image_raw for 10 s: it is published as "
        "sensor_msgs/msg/CompressedImage, not sensor_msgs/msg/Image" in log
    ), log[-3000:]
    assert "nothing arrived on /camera/camera/color/image_raw" not in log  # the colour and camera_info topics are fine
    assert log.count("without a depth image") <= 3, log[-3000:]  # a count every 5 s, not a line per colour image
