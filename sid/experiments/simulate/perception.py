"""What the robot learns about people at one step, and the costmap update that follows, in the map frame.

Each sensing is called with the step index, the robot's pose, the people's true poses and the step's LiDAR scan; it
updates its layered costmap and returns what the robot now believes (``Seen``):

- ``CameraSensing`` (the default with the social layer): ``sid.synthetic.sensor.SyntheticCamera`` renders the
  people as a D435i-like camera on the robot sees them from its current pose (``SIM_CALIBRATION``: 87 degree
  horizontal field of view, depth registered to a 640x360 colour grid, the D435 depth noise of
  ``sid.synthetic.noise``, noise drawn from ``[seed, step]``), and ``sid.stream.SocialStream`` runs on the frame:
  the real perception pipeline (``TruthPose`` with its documented keypoint noise, or an ONNX pose model), the
  people and group trackers, and the costmap with the tracked-people layer. The camera sees people only:
  obstacles are not rendered, so a wall hides nobody from it.
- ``ExactSensing``: the true poses and velocities of the people inside the camera's field of view and depth range
  whose centre or a side of the body the camera can see past obstacles and other people (rays in the LiDAR plane),
  the standing ones grouped by ``sid.perception.groups.detect_groups`` (walkers are in no conversation, as in the
  scene's truth), as perfect tracks on the tracked-people layer that the camera's tracks feed: a walker's cost is
  stretched along their true velocity. No noise, no tracking (out of view is forgotten). It isolates navigation
  from perception.
- ``LidarSensing`` (without the social layer): the scan alone.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from costmap.grid import Costmap2D
from costmap.layer import LayerInputs
from costmap.layered import LayeredCostmap
from costmap.layers.obstacle import SCAN
from costmap.layers.social import GROUPS, PEOPLE
from costmap.layers.tracked import TRACKS
from costmap.scan import LaserScan
from sid.perception.camera import Calibration, Extrinsics, Intrinsics
from sid.perception.group import Group
from sid.perception.groups import GroupParams, detect_groups
from sid.perception.people import Person
from sid.perception.robot_pose import RobotPose
from sid.scenario.lidar import simulate_scan
from sid.scenario.loader import Scenario
from sid.scenario.motion import Trajectory
from sid.scenario.obstacles import Obstacle
from sid.stream import SocialStream
from sid.synthetic.noise import DepthNoise
from sid.synthetic.sensor import SyntheticCamera
from sid.synthetic.sequence import SyntheticSequence
from sid.tracking.records import TrackedGroup, TrackedPerson, Tracks

__all__ = [
    "CameraSensing",
    "ExactSensing",
    "FIELD_OF_VIEW",
    "IMAGE_SIZE",
    "LidarSensing",
    "SIM_CALIBRATION",
    "Seen",
    "Sensing",
    "in_view",
    "sim_calibration",
]

FIELD_OF_VIEW = math.radians(87.0)
"""The D435i depth camera's horizontal field of view (rad)."""
IMAGE_SIZE = (640, 360)


def sim_calibration(fov: float = FIELD_OF_VIEW, size: tuple[int, int] = IMAGE_SIZE) -> Calibration:
    """A registered RGB-D calibration of ``size`` (width, height px) with horizontal field of view ``fov`` (rad)."""
    width, height = size
    fx = (width / 2) / math.tan(fov / 2)
    return Calibration(Intrinsics(width, height, fx, fx, (width - 1) / 2, (height - 1) / 2), None, Extrinsics(), 0.001)


SIM_CALIBRATION = sim_calibration()


@dataclass
class Seen:
    """What the robot believes after one step (map frame): people, conversational groups, and the camera's colour
    image (RGB) when there is one."""

    people: list[Person] = field(default_factory=list)
    groups: list[Group] = field(default_factory=list)
    image: np.ndarray | None = None


class Sensing(Protocol):
    costmap: LayeredCostmap

    def __call__(self, step: int, pose: RobotPose, people: list[Person], scan: LaserScan) -> Seen: ...


@dataclass
class LidarSensing:
    """The scan alone (no recognition)."""

    costmap: LayeredCostmap

    def __call__(self, step: int, pose: RobotPose, people: list[Person], scan: LaserScan) -> Seen:
        self.costmap.update(LayerInputs({SCAN: scan}))
        return Seen()


def in_view(pose: RobotPose, people: list[Person], fov: float, range_m: tuple[float, float]) -> list[Person]:
    """The people whose centre lies inside the camera's horizontal field of view and depth range."""
    if not people:
        return []
    base = pose.to_base(np.array([(p.x, p.y) for p in people]))
    bearing = np.arctan2(base[:, 1], base[:, 0])
    distance = np.hypot(base[:, 0], base[:, 1])
    keep = (np.abs(bearing) <= fov / 2) & (distance >= range_m[0]) & (distance <= range_m[1])
    return [p for p, k in zip(people, keep, strict=True) if k]


@dataclass
class ExactSensing:
    """True poses and velocities of the people in view and not hidden, as perfect tracks on the tracked-people layer
    (see the module docstring). ``walks``: the scene's scripted motion by person id (``Scenario.walks``);
    ``rate_hz``: steps per second, so that step ``k`` is time ``k / rate_hz`` (s)."""

    costmap: LayeredCostmap
    obstacles: list[Obstacle]
    group_params: GroupParams
    walks: dict[int, Trajectory]
    rate_hz: float
    body_radius: float = 0.2
    fov: float = FIELD_OF_VIEW
    range_m: tuple[float, float] = (DepthNoise().min_range_m, DepthNoise().max_range_m)
    walls: Costmap2D | None = None  # a static map file's walls (``sid.scenario.build.map_walls``): they hide people

    def __call__(self, step: int, pose: RobotPose, people: list[Person], scan: LaserScan) -> Seen:
        t = step / self.rate_hz
        seen, tracks = [], []
        for person in in_view(pose, people, self.fov, self.range_m):
            others = [p for p in people if p.id != person.id]
            if any(self._clear(pose, person, others, side) for side in (0.0, -0.8, 0.8)):
                walk = self.walks.get(person.id)
                state = None if walk is None else walk.at(t)
                vx, vy = (0.0, 0.0) if state is None else (state.vx, state.vy)
                walking = state is not None and state.moving
                seen.append(person)
                tracks.append(TrackedPerson(person.id, person.x, person.y, vx, vy, person.theta,
                                            "walking" if walking else "standing", True, True, t, person.id, 0.0,
                                            person.orientation_quality))  # fmt: skip
        standing = [p for p, track in zip(seen, tracks, strict=True) if not track.walking]
        groups = detect_groups(standing, self.group_params)
        conversations = [TrackedGroup(i, "conversation", g.members, g.interest_point, g.zone, g.area, g.spread,
                                      (0.0, 0.0), t) for i, g in enumerate(groups, start=1)]  # fmt: skip
        tracked = Tracks(tracks, conversations)
        self.costmap.update(LayerInputs({PEOPLE: seen, GROUPS: groups, SCAN: scan, TRACKS: tracked}))
        return Seen(seen, groups)

    def _clear(self, pose: RobotPose, person: Person, others: list[Person], side: float) -> bool:
        """Whether the ray from the camera to a point ``side`` body radii beside the person's centre is clear."""
        dx, dy = person.x - pose.x, person.y - pose.y
        distance = math.hypot(dx, dy)
        tx, ty = person.x - side * self.body_radius * dy / distance, person.y + side * self.body_radius * dx / distance
        bearing = math.atan2(ty - pose.y, tx - pose.x)
        # One beam: simulate_scan's beam 0 points at yaw - pi.
        scan = simulate_scan((pose.x, pose.y, bearing + math.pi), self.obstacles, others, beams=1,
                             range_max=2 * distance + 1.0, body_radius=self.body_radius, static=self.walls)  # fmt: skip
        target = math.hypot(tx - pose.x, ty - pose.y)
        return bool(not np.isfinite(scan.ranges[0]) or scan.ranges[0] > target - self.body_radius / 2)


class CameraSensing:
    """Rendered RGB-D frames through ``SocialStream`` (see the module docstring). ``camera.fps`` must be the
    simulation's rate, so that frame ``step`` shows the people at the step's time."""

    def __init__(self, stream: SocialStream, camera: SyntheticCamera, scenario: Scenario, seed: int = 0) -> None:
        self.stream, self.camera, self.seed = stream, camera, seed
        self.costmap = stream.costmap
        self.sequence = (
            SyntheticSequence.from_scenario(
                dataclasses.replace(scenario, robot=dataclasses.replace(scenario.robot, path=())), stream.pipeline.mount
            )  # fmt: skip
            if scenario.people
            else None
        )

    def __call__(self, step: int, pose: RobotPose, people: list[Person], scan: LaserScan) -> Seen:
        if self.sequence is None:  # nobody to see: the scan alone
            self.costmap.update(LayerInputs({SCAN: scan}))
            return Seen()
        here = dataclasses.replace(self.sequence, robot=Trajectory(pose.x, pose.y, pose.yaw))
        frame = self.camera.capture(here, step, self.seed)
        update = self.stream.update(frame, pose, scan)
        groups = [g.as_group() for g in update.groups if g.kind == "conversation"]
        return Seen([p.as_person() for p in update.people], groups, frame.color)
