"""What a scenario builds: its layered costmap (its known map and a simulated scan from the robot's start) and its
planning problem."""

from __future__ import annotations

import warnings

import numpy as np

from costmap.grid import Costmap2D
from costmap.layer import LayerInputs
from costmap.layered import LayeredCostmap
from costmap.layers.obstacle import SCAN
from costmap.layers.social import GROUPS, PEOPLE
from costmap.layers.static import static_costs
from costmap.layers.tracked import TRACKS
from costmap.mapfile import read_map
from costmap.occupancy import OccupancyGrid
from costmap.plugins import CostmapParams, layered_costmap
from planner.problem import DEFAULT_COST_WEIGHT, PlanningProblem
from sid.documents import InputWarning
from sid.perception.group import Group
from sid.scenario.known_map import known_map
from sid.scenario.lidar import simulate_scan
from sid.scenario.loader import Scenario
from sid.scenario.sight import Walls, known_walls, scenario_groups
from sid.tracking.records import still_tracks

__all__ = ["build_costmap", "map_walls", "planning_problem"]


def build_costmap(
    scenario: Scenario,
    social: bool = True,
    groups: list[Group] | None = None,
    params: CostmapParams | None = None,
) -> LayeredCostmap:
    """The costmap of a scenario: its known map, a simulated scan from the robot's start, people, groups and layers.

    The static layer holds the known map: every declared obstacle whole (rasterised by ``sid.scenario.known_map``)
    drawn into the ``static_map`` file, if any; without either there is no static layer. The LiDAR layer marks what
    the scan from the start sees (obstacles' near faces, the map file's walls, people).

    ``social`` False leaves the social layer out, and gives a tracked-people layer no tracks (a robot without
    recognition). ``groups`` None: detect them (only when ``social``), nobody grouped through a wall of the known
    map (``sid.scenario.sight.scenario_groups``). ``params`` None: the scenario's "layers" block.
    """
    params = params or scenario.layers
    if not social:
        params = params.without("social")
    static_map = None if scenario.static_map is None else read_map(scenario.static_map)
    known = None  # the static layer's map: the declared obstacles drawn into the map file (sid.scenario.known_map)
    if scenario.obstacles or static_map is not None:
        known = known_map(scenario.obstacles, scenario.grid, static_map)
    sight = None if known is None else known_walls(scenario, known)  # the known map's occupied cells
    if sight is not None:
        _warn_people_in_walls(scenario, sight)
    layered = layered_costmap(
        scenario.grid,
        params,
        robot_radius=scenario.robot.radius,
        body_radius=scenario.lidar.body_radius,
        static_map=known,
    )
    lidar = scenario.lidar
    walls = None if static_map is None else _walls(scenario, static_map)
    scan = simulate_scan(
        scenario.robot.start,
        scenario.obstacles,
        scenario.people,
        beams=lidar.beams,
        range_max=lidar.range_max,
        body_radius=lidar.body_radius,
        static=walls,
    )
    if groups is None:
        groups = scenario_groups(scenario, walls=sight) if social else []
    # A tracked-people layer draws the scene at rest: its people as standing tracks, its groups as conversations.
    tracks = still_tracks(scenario.people, groups) if social else None
    layered.update(LayerInputs({PEOPLE: scenario.people, GROUPS: groups, SCAN: scan, TRACKS: tracks}))
    return layered


def _warn_people_in_walls(scenario: Scenario, walls: Walls) -> None:
    """Warn of each person standing in an occupied cell of the known map (a declared obstacle or the map file's
    walls): nobody can stand there, so the people's positions or the map are likely in different frames or units;
    the costmap is drawn as given (``sid simulate``, whose scene is the true world, refuses such a person)."""
    cells = scenario.grid.world_to_cell(np.array([[p.x, p.y] for p in scenario.people]).reshape(-1, 2))
    for i, ((row, col), person) in enumerate(zip(cells.tolist(), scenario.people, strict=True)):
        if scenario.grid.in_bounds(np.array([row, col]))[0] and walls.occupied[row, col]:
            warnings.warn(
                f"people[{i}]: person {person.id} at ({person.x:g}, {person.y:g}) stands in an occupied cell of the "
                "known map (an obstacle or the static_map file's walls): are the people and the map in one frame?",
                InputWarning,
                stacklevel=3,
            )


def map_walls(scenario: Scenario) -> Costmap2D | None:
    """The scenario's ``static_map`` file on its grid, read as the static layer reads it: the walls (its LETHAL cells)
    that the simulated LiDAR hits whatever the costmap's layers; None without a file."""
    return None if scenario.static_map is None else _walls(scenario, read_map(scenario.static_map))


def _walls(scenario: Scenario, static_map: OccupancyGrid) -> Costmap2D:
    """``static_map`` (the scenario's file, read) on the scenario's grid as the static layer reads it."""
    track_unknown = scenario.layers.obstacle.track_unknown_space
    return Costmap2D(scenario.grid, static_costs(static_map, scenario.grid, track_unknown))


def planning_problem(
    scenario: Scenario, costmap: Costmap2D, cost_weight: float = DEFAULT_COST_WEIGHT
) -> PlanningProblem:
    """The scenario's robot task (start and goal positions, disc radius) on ``costmap``."""
    robot = scenario.robot
    return PlanningProblem(costmap, robot.start[:2], robot.goal[:2], robot.radius, cost_weight)
