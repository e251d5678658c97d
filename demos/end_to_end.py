"""The whole pipeline on one frame: camera frame -> people -> groups -> social costmap -> a path around them.

A synthetic RGB-D frame of the paper's layout S3 (three people in conversation, ~2 m in front of a camera 0.9 m
high) stands in for a RealSense frame, and its ground-truth keypoints (with pixel noise) for the pose model. On a
robot, swap in ``open_source("realsense")`` and ``image_pose(load_pose_estimator("model.onnx"))``. Everything is in
the world frame of the camera's footprint: x forward, y left, metres.
"""

from __future__ import annotations

from costmap.grid import GridSpec
from costmap.layer import LayerInputs
from costmap.layers.obstacle import SCAN
from costmap.layers.social import GROUPS, PEOPLE
from costmap.plugins import layered_costmap
from planner.facade import plan
from planner.problem import PlanningProblem
from sid.experiments.path_metrics import path_metrics
from sid.perception.mount import CameraMount
from sid.perception.pipeline import Pipeline
from sid.scenario.lidar import simulate_scan
from sid.sources.synthetic import SyntheticSource
from sid.synthetic.pose import TruthPose

# 1. Perception: one frame through pose -> 3D people -> groups.
frame = SyntheticSource("S3", frames=1, seed=0)[0]
result = Pipeline(TruthPose(), CameraMount(height=0.9))(frame)
for person in result.people:
    facing = "unknown" if person.theta is None else f"{person.theta:+.2f} rad"
    print(f"person {person.id}: x {person.x:.2f} m, y {person.y:+.2f} m, facing {facing}")
for group in result.groups:
    x, y = group.interest_point
    print(f"group {list(group.members)}: interest point ({x:.2f}, {y:+.2f}) m, spread {group.spread:.2f} m")
print("stage times (ms):", {stage: round(ms, 2) for stage, ms in result.timing_ms.items()})

# 2. Costmap: a 6 m x 5 m map around the camera, a LiDAR scan of the people, their social zones, inflation.
spec = GridSpec.from_size(0.05, origin=(-1.0, -2.5), size_m=(6.0, 5.0))
costmap = layered_costmap(spec, robot_radius=0.25)
costmap.update(
    LayerInputs({PEOPLE: result.people, GROUPS: result.groups, SCAN: simulate_scan((0.0, 0.0, 0.0), [], result.people)})
)

# 3. Planning: from the camera's position to a goal behind the group.
start, goal = (0.0, 0.0), (4.5, 0.0)
path = plan(PlanningProblem(costmap.master, start, goal, robot_radius=0.25), "grid")
metrics = path_metrics(path.path, result.people, result.groups)
print(
    f"path: {metrics['path_length_m']:.2f} m, {metrics['ospace_intrusion_m']:.2f} m inside group zones, "
    f"closest person {metrics['min_person_distance_m']:.2f} m"
)
