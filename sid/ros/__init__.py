"""ROS 2 integration (``sid ros``, the optional ``sid-social[ros]`` extra): a node that turns camera frames into a
social costmap Nav2 consumes as a KeepoutFilter mask, with its launch file, parameters and an example Nav2
configuration as package data (``sid/ros/data``). See docs/ros2.md.

``params`` and ``convert`` import no ROS; ``messages`` and ``node`` need rclpy and the ROS message packages.
"""
