"""``sid ros``: the ROS 2 node that publishes the social costmap for Nav2 (rclpy is imported only when it runs)."""

from __future__ import annotations

import argparse
import itertools
import sys
from collections.abc import Iterable
from pathlib import Path

from sid.cli.common import ExitCode, add_bag_topic_options, pose_model, positive_int, positive_number
from sid.distribution import install_hint
from sid.perception.frame import Frame
from sid.perception.pose.contracts import PoseModelError
from sid.sources import BAG_TOPICS, SourceError, open_source

__all__ = ["INSTALL_HINT", "SHARE", "SYNTHETIC_FRAMES", "add_parser", "run"]

INSTALL_HINT = (
    "sid ros needs ROS 2's rclpy, which cannot be imported here ({error}). Source a ROS 2 installation "
    f"(`source /opt/ros/jazzy/setup.bash`), or install the Python wheels with `{install_hint('ros')}`; see "
    "docs/ros2.md"
)
SYNTHETIC_FRAMES = 300
SHARE = Path(__file__).resolve().parents[1] / "ros" / "data"
"""sid/ros/data: sid.launch.py, sid_params.yaml, nav2_social_costmap.yaml."""


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "ros",
        help="run the ROS 2 node that publishes the social costmap for Nav2",
        description="Subscribe to realsense2_camera's colour, aligned depth and camera_info topics (or read --source), "
        "track people and groups, and publish /social_costmap (a Nav2 KeepoutFilter mask), RViz markers and the "
        "groups. Topics, frames and the costmap's size are ROS parameters (--ros-args --params-file FILE, or "
        "-p NAME:=VALUE); see docs/ros2.md.",
    )
    parser.add_argument(
        "--source", help="read frames from a sid source instead of topics: realsense | FILE | DIR | synthetic:SCENE"
    )
    add_bag_topic_options(parser)
    parser.add_argument("--model", type=Path, help="pose model (.onnx); optional only for a synthetic --source")
    parser.add_argument(
        "--frames", type=positive_int, help=f"stop the --source after this many frames (synthetic: {SYNTHETIC_FRAMES})"
    )
    parser.add_argument(
        "--rate",
        type=positive_number("frame rate in Hz", zero=True),
        default=0.0,
        metavar="HZ",
        help="play the --source at most this fast (0: as fast as processed)",
    )
    parser.add_argument(
        "--share", action="store_true", help="print the folder of the launch file and YAML files sid ships, and exit"
    )
    parser.add_argument(
        "--ros-args",
        dest="ros_args",
        nargs=argparse.REMAINDER,
        default=None,
        help="everything after it goes to ROS (e.g. --ros-args --params-file sid.yaml -p costmap.width:=30.0)",
    )
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.share:
        print(SHARE)
        return 0
    problem = _source_option_without_source(args)
    if problem:
        print(f"sid ros: {problem}", file=sys.stderr)
        return ExitCode.USAGE
    try:
        import rclpy
        from rclpy.impl.implementation_singleton import rclpy_implementation
        from rclpy.signals import SignalHandlerOptions

        from sid.ros.node import SocialCostmapNode, spin
        from sid.ros.params import rcl_reason
    except ImportError as exc:
        print(INSTALL_HINT.format(error=exc), file=sys.stderr)
        return ExitCode.MISSING_DEPENDENCY
    ros_args = ["--ros-args", *args.ros_args] if args.ros_args is not None else []
    try:  # sid's own handlers turn SIGINT and SIGTERM into KeyboardInterrupt (sid.cli.main); rclpy's would not.
        rclpy.init(args=["sid", *ros_args], signal_handler_options=SignalHandlerOptions.NO)
    except rclpy_implementation.RCLError as exc:  # a malformed -p, a --params-file that cannot be read
        print(f"sid ros: --ros-args: {rcl_reason(exc, 'failed to initialize rcl: ')}", file=sys.stderr)
        return ExitCode.USAGE
    node = None
    try:
        synthetic = args.source is not None and args.source.startswith("synthetic:")
        pose = pose_model(args.model, args.source)
        node = SocialCostmapNode(pose, camera_topics=args.source is None)
        frames: Iterable[Frame] | None = None
        if args.source is not None:
            topics = {name: getattr(args, name) for name in BAG_TOPICS}
            frames = open_source(
                args.source, **({"frames": args.frames or SYNTHETIC_FRAMES} if synthetic else {}), **topics
            )
            if args.frames is not None and not synthetic:
                frames = itertools.islice(frames, args.frames)
        stopped = spin(node, frames, args.rate)
        if stopped is not None:
            print(f"sid ros: source stopped: {stopped}", file=sys.stderr)
            return ExitCode.FAILURE
    except (SourceError, PoseModelError, ValueError, OSError) as exc:
        print(f"sid ros: {exc}", file=sys.stderr)
        return ExitCode.USAGE
    finally:
        if node is not None:
            node.node.destroy_node()
        rclpy.try_shutdown()
    return 0


def _source_option_without_source(args: argparse.Namespace) -> str | None:
    """What is wrong when an option that acts on ``--source`` is given without one (the node would ignore it: the
    camera topics are ROS parameters, and come at their own rate for as long as the node runs), or None."""
    if args.source is not None:
        return None
    for name in BAG_TOPICS:
        topic = getattr(args, name)
        if topic is not None:
            parameter = "camera_info_topic" if name == "info_topic" else name
            return (
                f"--{name.replace('_', '-')}: only a rosbag2 --source has topics to choose; the node subscribes to "
                f"the topics of its ROS parameters: --ros-args -p {parameter}:={topic}"
            )
    if args.rate:
        return "--rate: plays a --source; the camera topics come at their own rate"
    if args.frames is not None:
        return "--frames: stops a --source; without one, stop the node (Ctrl-C)"
    return None
