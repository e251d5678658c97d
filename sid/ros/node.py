"""The ``sid ros`` node: camera frames in, a Nav2 KeepoutFilter mask of the social costmap out.

Per frame (one call, ``SocialCostmapNode.on_frame``): the robot pose at the frame's time, then
``sid.stream.SocialStream.update`` (pose -> people -> groups, the trackers, the tracked-people costmap layer), then
the publications: the mask on ``costmap_topic`` (reliable, transient local, depth 1, in ``global_frame``), the
``nav2_msgs/CostmapFilterInfo`` announcing it (when nav2_msgs is importable; latched), RViz markers, and the groups
as JSON on ``groups_topic`` (plus REP-155's ``/humans/groups/tracked`` when hri_msgs is importable).

Frames come from the camera topics (colour, aligned depth, camera_info; paired by stamp) or, with ``source``, from
any sid source read in a thread. With ``pose_source`` auto, a frame that carries its own robot pose (a recording
with odometry, a synthetic sequence) uses it; else the TF or odometry pose; while neither has arrived, the robot is
taken as fixed at ``global_frame``'s origin (one warning says how to set ``pose_source``). A frame that fails (bad
image, no pose yet with pose_source tf or odom, out of time order) is logged and skipped; the node keeps running.
Per-stage timing is logged at debug level.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterable
from typing import Any

import rclpy
from nav_msgs.msg import OccupancyGrid, Odometry
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from rclpy.time import Time as RosTime
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from sid.documents import plural
from sid.errors import InputError
from sid.perception.camera import Intrinsics
from sid.perception.frame import Frame
from sid.perception.pipeline import Pipeline, PoseFn
from sid.perception.robot_pose import RobotPose
from sid.ros import messages
from sid.ros.convert import grid_fields, groups_document, scene_markers, yaw_from_quaternion
from sid.ros.params import NODE_NAME, read_params
from sid.sources import FrameReadError, SourceError, skip_unreadable
from sid.sources.ros_messages import (
    StampPairer,
    intrinsics_from_camera_info,
    is_rectified_topic,
    rgbd_frame,
    stamp_seconds,
)
from sid.stream import SocialStream, StreamUpdate

__all__ = ["LATCHED", "NO_DEPTH_REPORT", "SILENCE_REPORT", "SPIN_WAIT", "SocialCostmapNode", "spin"]

LATCHED = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=1,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)
"""What map topics offer, and Nav2's costmap filters expect of a mask and its filter info."""
SPIN_WAIT = 0.2
"""Longest wait (s) for a callback before the spin loop returns to Python (and to its signal handlers)."""
SILENCE_REPORT = 10.0
"""Period (s) of the check that each camera topic received something; a silent one is logged with the reason."""
NO_DEPTH_REPORT = 5.0
"""Shortest period (s) between two counts of colour images skipped for want of a depth image."""


class SocialCostmapNode:
    """The node (see the module docstring), as ``self.node``. ``pose``: the pose model. ``camera_topics``: subscribe
    to the camera (False when frames come from ``feed``). Needs ``rclpy.init()`` first."""

    def __init__(self, pose: PoseFn, camera_topics: bool = True) -> None:
        self.node: Node = rclpy.create_node(NODE_NAME)
        self.params = p = read_params(self.node)
        self.pose = pose
        pipeline = Pipeline(pose, p.mount, group_params=p.groups, group=False)  # the group tracker groups the tracks
        self.stream = SocialStream(pipeline, p.grid, p.layers, params=p.tracking)
        self.fixed_robot = False
        """Whether frames are placed with the robot fixed at the origin (pose_source auto, no pose arrived yet)."""
        self.frames = 0
        self.source_stopped = threading.Event()
        """Set by ``feed`` when its source stopped with an error (``source_error``); ``spin`` then returns."""
        self.source_error: SourceError | None = None
        self.costmap_pub = self.node.create_publisher(OccupancyGrid, p.costmap_topic, LATCHED)
        self.markers_pub = self.node.create_publisher(MarkerArray, p.markers_topic, 10)
        self.groups_pub = self.node.create_publisher(String, p.groups_topic, 10)
        info_type = messages.filter_info_type()
        if info_type is not None:
            info = messages.filter_info(
                info_type, p.costmap_topic, p.global_frame, self.node.get_clock().now().to_msg()
            )
            self.node.create_publisher(info_type, p.filter_info_topic, LATCHED).publish(info)
        self.ids_type = messages.ids_list_type()
        self.hri_pub = (
            None if self.ids_type is None else self.node.create_publisher(self.ids_type, "/humans/groups/tracked", 10)
        )
        self.pose_source = self._pose_source()
        self.odometry: Odometry | None = None
        if self.pose_source == "tf":
            import tf2_ros

            self.tf_buffer = tf2_ros.Buffer()
            self.tf_listener = tf2_ros.TransformListener(
                self.tf_buffer, self.node, spin_thread=True
            )  # waits never block it
        elif self.pose_source == "odom":
            self.node.create_subscription(Odometry, p.odom_topic, self._on_odometry, 10)
        self.intrinsics: Intrinsics | None = None
        self.pairer: StampPairer[Image] = StampPairer(p.sync_tolerance)
        self.received = {"color": 0, "depth": 0, "info": 0}
        """Messages received per camera topic (``_report_silence`` compares them with the last check's)."""
        self._checked = dict(self.received)
        self._no_depth = 0  # colour images skipped for want of depth since the last count was logged
        self._no_depth_logged = -float("inf")  # time.monotonic() of that log
        if camera_topics:
            self.node.create_timer(SILENCE_REPORT, self._report_silence)
            self.node.create_subscription(
                CameraInfo, p.camera_info_topic, self._on_camera_info, qos_profile_sensor_data
            )
            self.node.create_subscription(
                Image, p.color_topic, lambda m: self._on_image("color", m), qos_profile_sensor_data
            )
            self.node.create_subscription(
                Image, p.depth_topic, lambda m: self._on_image("depth", m), qos_profile_sensor_data
            )
        self.node.get_logger().info(
            f"publishing {p.costmap_topic} in {p.global_frame} ({p.grid.width}x{p.grid.height} cells of "
            f"{p.grid.resolution} m); robot pose from {self.pose_source}; filter info: "
            f"{'on ' + p.filter_info_topic if info_type else 'off (nav2_msgs not importable)'}"
        )
        if camera_topics:  # nothing more is logged until the first colour and depth pair arrives
            self.node.get_logger().info(
                f"waiting for {p.camera_info_topic}, {p.color_topic} and {p.depth_topic} (realsense2_camera's topics; "
                "remap them with --ros-args -p color_topic:=... if yours differ)"
            )

    def _pose_source(self) -> str:
        chosen = self.params.pose_source
        if chosen in ("auto", "tf"):
            try:
                import tf2_ros  # noqa: F401 - only whether it imports
            except ImportError:
                if chosen == "tf":
                    raise InputError("pose_source 'tf' needs tf2_ros, which is not importable") from None
                return "odom"
            return "tf"
        return chosen

    def _on_odometry(self, msg: Odometry) -> None:
        """Keep the latest odometry; warn once when its frame is not ``global_frame`` (the pose is used as one in
        ``global_frame`` all the same: the mask is then off by the transform between the two frames)."""
        frame = msg.header.frame_id.lstrip("/")
        if self.odometry is None and frame and frame != self.params.global_frame:
            self.node.get_logger().warning(
                f"odometry on {self.params.odom_topic} is in frame {frame!r}, not global_frame "
                f"{self.params.global_frame!r}: its pose is used as the pose in {self.params.global_frame}, so the "
                f"mask is off by the {self.params.global_frame} -> {frame} transform; set -p global_frame:={frame} "
                "to publish the mask in that frame, or -p pose_source:=tf"
            )
        self.odometry = msg

    def _on_camera_info(self, msg: CameraInfo) -> None:
        self.received["info"] += 1
        try:
            self.intrinsics = intrinsics_from_camera_info(msg, is_rectified_topic(self.params.color_topic))
        except ValueError as exc:
            self.node.get_logger().error(f"{self.params.camera_info_topic}: {exc}", throttle_duration_sec=5.0)

    def _report_silence(self) -> None:
        """Warn of each camera topic that received nothing since the last check, ``SILENCE_REPORT`` s ago, with the
        reason the ROS graph gives: no publisher (which topics of the type are published), or publishers of another
        type (image_transport's CompressedImage)."""
        p = self.params
        for stream, topic, expected in (
            ("color", p.color_topic, "sensor_msgs/msg/Image"),
            ("depth", p.depth_topic, "sensor_msgs/msg/Image"),
            ("info", p.camera_info_topic, "sensor_msgs/msg/CameraInfo"),
        ):
            if self.received[stream] == self._checked[stream]:
                name = self.node.resolve_topic_name(topic)
                reason = self._silence_reason(stream, name, expected)
                self.node.get_logger().warning(f"nothing arrived on {name} for {SILENCE_REPORT:g} s: {reason}")
        self._checked = dict(self.received)

    def _silence_reason(self, stream: str, topic: str, expected: str) -> str:
        """Why nothing arrives on ``topic`` (a resolved name) of type ``expected``, as far as the ROS graph tells."""
        publishers = self.node.get_publishers_info_by_topic(topic)
        types = sorted({info.topic_type for info in publishers})
        if not types:
            published = sorted(
                name
                for name, kinds in self.node.get_topic_names_and_types()
                if expected in kinds and name != topic and self.node.count_publishers(name)
            )
            hint = " (realsense2_camera publishes it with align_depth.enable:=true)" if stream == "depth" else ""
            return (
                f"no node publishes it{hint}; {expected} topics published: {', '.join(published) or 'none'} (choose "
                f"with -p {stream if stream != 'info' else 'camera_info'}_topic:=...)"
            )
        if expected not in types:
            return (
                f"it is published as {', '.join(types)}, not {expected}; sid reads only raw images (republish them as "
                "raw: docs/ros2.md, section 5)"
            )
        return f"{plural(len(publishers), 'publisher')} of {expected}, but no message came (a QoS or network problem?)"

    def _on_image(self, stream: str, msg: Image) -> None:
        self.received[stream] += 1
        pair = self.pairer.add(stream, stamp_seconds(msg.header), msg)
        if self.pairer.dropped_colors:
            self._no_depth += len(self.pairer.dropped_colors)
            now = time.monotonic()
            if now - self._no_depth_logged >= NO_DEPTH_REPORT:
                self.node.get_logger().warning(
                    f"{plural(self._no_depth, 'colour image')} skipped without a depth image on "
                    f"{self.params.depth_topic} within {self.pairer.tolerance:g} s of it (the last at "
                    f"{self.pairer.dropped_colors[-1].stamp:.3f} s)"
                )
                self._no_depth, self._no_depth_logged = 0, now
        for dropped in self.pairer.duplicate_colors:
            self.node.get_logger().warning(f"colour image at {dropped.stamp:.3f} s repeats another's stamp; skipped")
        for dropped in self.pairer.late_colors:
            self.node.get_logger().warning(
                f"colour image at {dropped.stamp:.3f} s is older than the last frame "
                f"({self.pairer.last_color_stamp:.3f} s): the stamps went back; skipped"
            )
        self.pairer.dropped_colors.clear()
        self.pairer.duplicate_colors.clear()
        self.pairer.late_colors.clear()
        if pair is None:
            return
        index, self.frames = self.frames, self.frames + 1
        if self.intrinsics is None:
            self.node.get_logger().warning("no camera_info yet; frame skipped", throttle_duration_sec=5.0)
            return
        color, depth = pair
        try:
            frame = rgbd_frame(index, color.item, depth.item, self.intrinsics, self.params.depth_scale)
        except ValueError as exc:
            self.node.get_logger().error(f"frame {index}: skipped, {exc}")
            return
        self.on_frame(frame, color.item.header.stamp)

    def robot_pose(self, stamp: Any | None, wait: bool = True) -> RobotPose | None:
        """base_frame's pose in global_frame, or None when it is not known yet. Pose source tf: the transform at
        ``stamp`` (a builtin_interfaces/Time; None: the latest), waiting up to ``transform_timeout`` for it when
        ``wait``; odom: the latest odometry message, whatever ``stamp``; none: the origin."""
        if self.pose_source == "none":
            return RobotPose(0.0, 0.0, 0.0)
        if self.pose_source == "odom":
            odometry = self.odometry
            if odometry is None:
                return None
            pose = odometry.pose.pose
            q = pose.orientation
            return RobotPose(pose.position.x, pose.position.y, yaw_from_quaternion(q.x, q.y, q.z, q.w))
        import tf2_ros
        from rclpy.duration import Duration

        when = RosTime() if stamp is None else RosTime.from_msg(stamp)
        try:
            t = self.tf_buffer.lookup_transform(
                self.params.global_frame,
                self.params.base_frame,
                when,
                timeout=Duration(seconds=self.params.transform_timeout if wait else 0.0),
            )
        except tf2_ros.TransformException as exc:
            if wait:
                self.node.get_logger().warning(f"no transform: {exc}", throttle_duration_sec=5.0)
            return None
        q = t.transform.rotation
        return RobotPose(t.transform.translation.x, t.transform.translation.y, yaw_from_quaternion(q.x, q.y, q.z, q.w))

    def on_frame(self, frame: Frame, stamp: Any | None = None) -> None:
        """The per-frame work: pose, stream update, publications. ``stamp``: the images' header stamp (None: now,
        for frames read from a source). A failing frame is logged and skipped."""
        try:
            pose = self.frame_pose(frame, stamp)
            if pose is None:
                self.node.get_logger().warning(
                    f"frame {frame.index}: skipped, no robot pose yet ({self._pose_origin()})",
                    throttle_duration_sec=5.0,
                )
                return
            update = self.stream.update(frame, pose)
            self.publish(update, stamp if stamp is not None else self.node.get_clock().now().to_msg())
        except Exception as exc:  # a bad frame must not stop the node: report it and go on
            self.node.get_logger().error(f"frame {frame.index}: skipped, {type(exc).__name__}: {exc}")
            return
        timing = ", ".join(f"{k} {v:.1f}" for k, v in update.timing_ms.items())
        self.node.get_logger().debug(
            f"frame {frame.index}: {plural(len(update.people), 'person', 'people')}, "
            f"{plural(len(update.groups), 'group')}; ms: {timing}"
        )

    def frame_pose(self, frame: Frame, stamp: Any | None) -> RobotPose | None:
        """The robot pose ``frame`` is placed with (see the module docstring), or None: skip it."""
        if self.params.pose_source != "auto":
            return self.robot_pose(stamp)
        if frame.robot_pose is not None:
            return frame.robot_pose
        pose = self.robot_pose(stamp, wait=not self.fixed_robot)
        log = self.node.get_logger()
        if pose is None and not self.fixed_robot:
            self.fixed_robot = True
            log.warning(
                f"frame {frame.index}: no robot pose ({self._pose_origin()}, pose_source auto) and none in the "
                f"frames: the robot is taken as fixed at the origin of {self.params.global_frame} until one arrives. "
                "Set pose_source: -p pose_source:=none for a fixed camera, odom or tf to wait for the robot's pose"
            )
        elif pose is not None and self.fixed_robot:
            self.fixed_robot = False
            log.info(f"frame {frame.index}: robot pose from {self.pose_source} from now on; tracking starts afresh")
            self.stream.reset()  # the tracks were placed with the robot at the origin; new ones get new ids
        return pose if pose is not None else RobotPose(0.0, 0.0, 0.0)

    def _pose_origin(self) -> str:
        """Where the robot pose is awaited from, for a message (``odometry on /odom``)."""
        if self.pose_source == "odom":
            return f"odometry on {self.params.odom_topic}"
        return f"a TF transform {self.params.global_frame} -> {self.params.base_frame}"

    def publish(self, update: StreamUpdate, stamp: Any) -> None:
        """The mask, the markers and the groups of one update, stamped ``stamp``."""
        frame_id = self.params.global_frame
        self.costmap_pub.publish(messages.occupancy_grid(grid_fields(update.costmap, frame_id), stamp))
        markers = scene_markers(update.people, update.groups, self.params.layers.social.group_margin)
        self.markers_pub.publish(messages.marker_array(markers, frame_id, stamp))
        seconds = stamp.sec + stamp.nanosec * 1e-9
        document = groups_document(seconds, frame_id, update.people, update.groups)
        self.groups_pub.publish(String(data=json.dumps(document)))
        if self.hri_pub is not None and self.ids_type is not None:
            ids = [str(g.id) for g in update.groups]
            self.hri_pub.publish(self.ids_type(header=messages.header(frame_id, stamp), ids=ids))

    def feed(self, frames: Iterable[Frame], rate: float = 0.0) -> None:
        """Run every frame of a sid source through ``on_frame`` (unreadable ones logged and skipped), at most
        ``rate`` frames per second (0: as fast as they come). A source that stops with a SourceError (a camera
        failing again and again, a damaged recording) is kept as ``source_error`` and ``source_stopped`` is set."""

        def report(error: FrameReadError) -> None:
            self.node.get_logger().error(f"frame {error.index}: skipped, {error}")

        period = 1.0 / rate if rate > 0 else 0.0
        try:
            for frame in skip_unreadable(frames, report):
                start = time.monotonic()
                if not rclpy.ok():
                    return
                self.on_frame(frame)
                while rclpy.ok() and (left := period - (time.monotonic() - start)) > 0:
                    time.sleep(min(left, SPIN_WAIT))  # in short waits: a period of 1e300 s would overflow time.sleep
        except SourceError as exc:
            self.source_error = exc
            self.source_stopped.set()
            return
        self.node.get_logger().info("source ended; the last costmap stays published")


def spin(node: SocialCostmapNode, frames: Iterable[Frame] | None = None, rate: float = 0.0) -> SourceError | None:
    """Spin ``node`` until shutdown, KeyboardInterrupt or its source stopping with an error; with ``frames``, feed
    them from a thread meanwhile. Returns the SourceError that stopped the source, or None.

    Spins in short waits, so the signal handlers of ``sid.cli`` (SIGINT, SIGTERM -> KeyboardInterrupt) run."""
    if frames is not None:
        threading.Thread(target=node.feed, args=(frames, rate), daemon=True, name="sid-source").start()
    while rclpy.ok() and not node.source_stopped.is_set():
        rclpy.spin_once(node.node, timeout_sec=SPIN_WAIT)
    return node.source_error
