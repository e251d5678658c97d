"""sid: social interaction detection from a single RGB-D camera.

Data flows one way: source -> pose -> people -> groups -> costmap layers -> planner -> metrics/pictures.
Each stage lives in its own module and can be used alone; the names a robotics user needs are here:

>>> import sid
>>> pipeline = sid.Pipeline(sid.image_pose(sid.load_pose_estimator("yolo11n-pose-256.onnx")), sid.CameraMount(0.9))
>>> for frame in sid.open_source("recording.db3"):
...     result = pipeline(frame)  # result.people, result.groups (result.frame_id: "map" or "base_footprint")
>>> stream = sid.SocialStream(pipeline, costmap_grid_spec)  # tracks and a costmap that holds still, frame after frame
>>> scenario = sid.load_scenario("examples/conversation.json")
>>> layered = sid.build_costmap(scenario)
>>> result = sid.plan(sid.planning_problem(scenario, layered.master), planner="bitstar", time_limit=0.5, seed=1)

They load on first use, so ``import sid`` itself imports neither onnxruntime, OMPL nor OpenCV.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

# Public name -> the module that defines it.
_EXPORTS: dict[str, str] = {
    "Pipeline": "sid.perception.pipeline",
    "image_pose": "sid.perception.pipeline",
    "open_source": "sid.sources",
    "Frame": "sid.perception.frame",
    "load_pose_estimator": "sid.perception.pose",
    "CameraMount": "sid.perception.mount",
    "Calibration": "sid.perception.camera",
    "Person": "sid.perception.people",
    "Group": "sid.perception.group",
    "GroupParams": "sid.perception.groups",
    "detect_groups": "sid.perception.groups",
    "LayeredCostmap": "costmap.layered",
    "CostmapParams": "costmap.plugins",
    "build_costmap": "sid.scenario.build",
    "load_scenario": "sid.scenario.loader",
    "Scenario": "sid.scenario.loader",
    "planning_problem": "sid.scenario.build",
    "plan": "planner.facade",
    "PlanResult": "planner.facade",
    "PlanningProblem": "planner.problem",
    "RobotPose": "sid.perception.robot_pose",
    "SocialStream": "sid.stream",
    "StreamUpdate": "sid.stream",
    "PeopleTracker": "sid.tracking.tracker",
    "TrackingParams": "sid.tracking.session",
}

__all__ = sorted(_EXPORTS)

if TYPE_CHECKING:  # what type checkers see; ``as`` marks each as re-exported
    from costmap.layered import LayeredCostmap as LayeredCostmap
    from costmap.plugins import CostmapParams as CostmapParams
    from planner.facade import PlanResult as PlanResult
    from planner.facade import plan as plan
    from planner.problem import PlanningProblem as PlanningProblem
    from sid.perception.camera import Calibration as Calibration
    from sid.perception.frame import Frame as Frame
    from sid.perception.group import Group as Group
    from sid.perception.groups import GroupParams as GroupParams
    from sid.perception.groups import detect_groups as detect_groups
    from sid.perception.mount import CameraMount as CameraMount
    from sid.perception.people import Person as Person
    from sid.perception.pipeline import Pipeline as Pipeline
    from sid.perception.pipeline import image_pose as image_pose
    from sid.perception.pose import load_pose_estimator as load_pose_estimator
    from sid.perception.robot_pose import RobotPose as RobotPose
    from sid.scenario.build import build_costmap as build_costmap
    from sid.scenario.build import planning_problem as planning_problem
    from sid.scenario.loader import Scenario as Scenario
    from sid.scenario.loader import load_scenario as load_scenario
    from sid.sources import open_source as open_source
    from sid.stream import SocialStream as SocialStream
    from sid.stream import StreamUpdate as StreamUpdate
    from sid.tracking.session import TrackingParams as TrackingParams
    from sid.tracking.tracker import PeopleTracker as PeopleTracker


if not TYPE_CHECKING:  # hidden from type checkers, which would read any misspelt ``sid.X`` as this function's Any

    def __getattr__(name: str) -> Any:
        """Import a public name's module on first access (PEP 562) and keep the name here."""
        module = _EXPORTS.get(name)
        if module is None:
            raise AttributeError(f"module 'sid' has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        globals()[name] = value
        return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})
