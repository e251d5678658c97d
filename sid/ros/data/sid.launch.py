"""Launch ``sid ros`` with the shipped parameters (ROS 2 launch file).

    ros2 launch "$(sid ros --share)/sid.launch.py" model:=/path/to/yolo11n-pose.onnx [params_file:=my_params.yaml]

``sid`` is a Python package, not an ament one, so the node runs as a process (``sid ros``), not as a launch_ros Node.
"""

from importlib.resources import files

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.substitutions import LaunchConfiguration

__all__ = ["generate_launch_description"]


def generate_launch_description() -> LaunchDescription:
    defaults = str(files("sid.ros") / "data" / "sid_params.yaml")
    return LaunchDescription(
        [
            DeclareLaunchArgument("model", description="pose model (.onnx), see docs/models.md"),
            DeclareLaunchArgument("params_file", default_value=defaults, description="sid ros parameters YAML"),
            ExecuteProcess(
                cmd=[
                    "sid",
                    "ros",
                    "--model",
                    LaunchConfiguration("model"),
                    "--ros-args",
                    "--params-file",
                    LaunchConfiguration("params_file"),
                ],
                name="sid_social_costmap",
                output="screen",
            ),
        ]
    )
