"""What a scenario builds: its layered costmap (a simulated scan from the robot's start) and its planning problem."""

from __future__ import annotations

from costmap.grid import Costmap2D
from costmap.layered import CostmapParams, LayeredCostmap
from costmap.layers.static import static_costs
from costmap.mapfile import read_map
from planner.problem import DEFAULT_COST_WEIGHT, PlanningProblem
from sid.perception.groups import Group
from sid.scenario.lidar import simulate_scan
from sid.scenario.loader import Scenario


def build_costmap(
    scenario: Scenario,
    social: bool = True,
    groups: list[Group] | None = None,
    params: CostmapParams | None = None,
) -> LayeredCostmap:
    """The costmap of a scenario: a simulated scan from the robot's start pose, people, groups and layers.

    ``groups`` None: detect them with ``sid.perception.groups.detect_groups`` (only when ``social``). ``params`` None:
    the
    scenario's "layers" block.
    """
    params = params or scenario.layers
    static = None
    if scenario.static_map is not None:
        static = static_costs(read_map(scenario.static_map), scenario.grid, params.obstacle.track_unknown_space)
    layered = LayeredCostmap(
        scenario.grid,
        params,
        robot_radius=scenario.robot.radius,
        body_radius=scenario.lidar.body_radius,
        social=social,
        static=static,
    )
    lidar = scenario.lidar
    scan = simulate_scan(
        scenario.robot.start,
        scenario.obstacles,
        scenario.people,
        beams=lidar.beams,
        range_max=lidar.range_max,
        body_radius=lidar.body_radius,
        static=None if static is None else Costmap2D(scenario.grid, static),
    )
    if groups is None:
        if social:
            from sid.perception.groups import detect_groups  # the group detector is only needed with recognition

            groups = detect_groups(scenario.people, scenario.group_params)
        else:
            groups = []
    layered.update(scenario.people, groups, scan)
    return layered


def planning_problem(
    scenario: Scenario, costmap: Costmap2D, cost_weight: float = DEFAULT_COST_WEIGHT
) -> PlanningProblem:
    """The scenario's robot task (start and goal positions, disc radius) on ``costmap``."""
    robot = scenario.robot
    return PlanningProblem(costmap, robot.start[:2], robot.goal[:2], robot.radius, cost_weight)
