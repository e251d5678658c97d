"""Plan past three people in conversation, without and with the social layer, using the library directly.

Run: python demos/plan_around_group.py   (no arguments; writes plan_around_group.png in the current folder)
"""

from __future__ import annotations

import cv2

from planner.facade import plan
from sid.experiments.demo import demo_scenario
from sid.experiments.path_metrics import path_metrics
from sid.experiments.path_render import WITH_COLOUR, WITHOUT_COLOUR, PathStyle, render_paths
from sid.perception.groups import detect_groups
from sid.scenario.build import build_costmap, planning_problem

# The built-in scenario: a corridor, the robot at (0, 0), its goal at (9, 0) behind a conversation of three.
scenario = demo_scenario()
groups = detect_groups(scenario.people, scenario.group_params)
print(f"{len(scenario.people)} people, groups found: {[g.members for g in groups]}")

paths = []
for social, colour in ((False, WITHOUT_COLOUR), (True, WITH_COLOUR)):
    # The costmap the robot sees: the known map and LiDAR, plus the social layer from the recognised groups.
    costmap = build_costmap(scenario, social=social, groups=groups if social else [])
    problem = planning_problem(scenario, costmap.master)
    # BIT* with a fixed seed and iteration cap: the same path on every run.
    result = plan(problem, "bitstar", time_limit=5.0, seed=1, max_iterations=5000)
    m = path_metrics(result.path, scenario.people, groups)
    label = "with social layer" if social else "map + LiDAR"
    print(
        f"{label:18s}: {m['path_length_m']:.2f} m, {m['ospace_intrusion_m']:.2f} m inside the group zone, "
        f"closest person {m['min_person_distance_m']:.2f} m"
    )
    paths.append((result.path, PathStyle(label, colour, dashed=not social)))

picture, _ = render_paths(costmap, paths, robot=scenario.robot, groups=groups, title="dashed: map + LiDAR only")
cv2.imwrite("plan_around_group.png", picture)
print("wrote plan_around_group.png")
