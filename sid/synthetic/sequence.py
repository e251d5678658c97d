"""Moving synthetic scenes: people and the robot carrying the camera follow scripted paths in the map frame.

A ``SyntheticSequence`` is read from a costmap scenario file (``sid.scenario.loader``): its people (standing or walking
along ``people[i].path``), its robot (standing at ``robot.start`` or driving along ``robot.path``) and its declared
``conversations``. ``SyntheticSequence.at(t)`` gives the ``Moment`` the camera renders at time t: the robot's pose,
everyone's map-frame pose and velocity, and the conversations that hold then. A declared conversation holds while all
its members stand (walkers are in no conversation). The scenario's obstacles are not rendered: the camera sees the
people on open ground. Metres, radians, seconds.

Built-in sequences (scenario files shipped in ``sid/synthetic/sequences``, loaded by name with ``builtin_sequence``
or ``synthetic:NAME``): ``crossing_walkers`` (two conversations, three walkers crossing the view and hiding them for
a while), ``drive_past_group`` (the robot drives past a conversation of three), ``walking_pairs`` (two people walking
in file, two side by side), ``file_behind_group`` (two walkers in file passing behind a conversation of three, hidden
by it for longer than the tracker's timeout), ``close_crossing`` (two walkers crossing under 0.4 m apart, one in front
of the other).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sid.documents import load_document
from sid.errors import InputError
from sid.perception.mount import CameraMount
from sid.perception.robot_pose import RobotPose
from sid.scenario.loader import Scenario, ScenarioError, scenario_from_dict
from sid.scenario.motion import MotionState, Trajectory
from sid.synthetic.scene import Scene, ScenePerson

__all__ = [
    "Moment",
    "MovingPerson",
    "SEQUENCES",
    "SEQUENCES_DIR",
    "SyntheticSequence",
    "builtin_sequence",
    "load_scene_file",
]

SEQUENCES_DIR = Path(__file__).parent / "sequences"
SEQUENCES = ("crossing_walkers", "drive_past_group", "walking_pairs", "file_behind_group", "close_crossing")


@dataclass(frozen=True)
class MovingPerson:
    """A person following ``trajectory`` (map frame), ``height`` m tall."""

    id: int
    trajectory: Trajectory
    height: float = 1.70


@dataclass(frozen=True)
class Moment:
    """A sequence at one time (s): the robot's pose (base_footprint in the map), every person's map-frame state
    (position, facing, velocity), the same people as ``ScenePerson``s in the map and in base_footprint (what the
    camera renders), and the declared conversations that hold (tuples of person ids)."""

    time: float
    robot_pose: RobotPose
    states: dict[int, MotionState]
    people: tuple[ScenePerson, ...]
    seen_people: tuple[ScenePerson, ...]
    groups: tuple[tuple[int, ...], ...]


@dataclass(frozen=True)
class SyntheticSequence:
    """People and a camera-carrying robot moving in the map frame (module docstring).

    robot: the motion of base_footprint in the map. conversations: declared groups (person ids). mount: the camera
    on the robot. Every person needs a facing (theta) or a path.
    """

    name: str
    people: tuple[MovingPerson, ...]
    robot: Trajectory
    conversations: tuple[tuple[int, ...], ...] = ()
    mount: CameraMount = field(default_factory=CameraMount)

    def __post_init__(self) -> None:
        if not self.people:
            raise InputError(f"sequence {self.name}: no people to render")
        ids = [p.id for p in self.people]
        if len(set(ids)) != len(ids):
            raise InputError(f"sequence {self.name}: person ids must be unique, got {ids}")
        unknown = [p.id for p in self.people if p.trajectory.yaw is None and not p.trajectory.path]
        if unknown:
            raise InputError(f"sequence {self.name}: people {unknown} have no facing direction (theta) and no path")
        for group in self.conversations:
            missing = set(group) - set(ids)
            if missing:
                raise InputError(f"sequence {self.name}: conversation {group} names unknown people {sorted(missing)}")

    @classmethod
    def from_scenario(cls, scenario: Scenario, mount: CameraMount | None = None) -> SyntheticSequence:
        """The people, robot motion and conversations of a ``sid.scenario.loader.Scenario``."""
        people = tuple(MovingPerson(p.id, scenario.trajectory(p)) for p in scenario.people)
        try:
            return cls(scenario.name, people, scenario.robot.trajectory, scenario.conversations, mount or CameraMount())
        except ValueError as exc:
            raise InputError(f"scenario {exc}") from None

    @property
    def duration(self) -> float:
        """Time (s) until the last mover stops (0 when nobody moves)."""
        return max([self.robot.end_time, *(p.trajectory.end_time for p in self.people)])

    def at(self, t: float) -> Moment:
        """The sequence at time ``t`` (s)."""
        robot = self.robot.at(t)
        assert robot.yaw is not None  # a scenario's robot start always has a yaw
        pose = RobotPose(robot.x, robot.y, robot.yaw)
        states = {p.id: p.trajectory.at(t) for p in self.people}
        people, seen = [], []
        for person in self.people:
            state = states[person.id]
            assert state.yaw is not None  # checked in __post_init__: a theta or a path
            people.append(ScenePerson(person.id, state.x, state.y, state.yaw, person.height))
            (x, y) = pose.to_base(np.array([state.x, state.y]))[0].tolist()
            seen.append(ScenePerson(person.id, x, y, math.remainder(state.yaw - pose.yaw, math.tau), person.height))
        groups = tuple(g for g in self.conversations if not any(states[m].moving for m in g))
        return Moment(t, pose, states, tuple(people), tuple(seen), groups)


def builtin_sequence(name: str) -> SyntheticSequence:
    """One of the built-in sequences (``SEQUENCES``) by name."""
    if name not in SEQUENCES:
        raise InputError(f"unknown built-in sequence {name!r}; known: {', '.join(SEQUENCES)}")
    scene = load_scene_file(SEQUENCES_DIR / f"{name}.yaml")
    assert isinstance(scene, SyntheticSequence)  # the shipped files are scenarios
    return scene


def load_scene_file(path: str | Path) -> Scene | SyntheticSequence:
    """A scene file as a static ``Scene``, or a costmap scenario file (it has a ``robot``) as a ``SyntheticSequence``.

    Raises ValueError naming the file and the problem."""
    path = Path(path)
    data = load_document(path, "scene file")
    if not (isinstance(data, dict) and "robot" in data):
        return Scene.from_file(path)
    try:
        return SyntheticSequence.from_scenario(scenario_from_dict(data, path.parent, path.stem))
    except (ScenarioError, ValueError) as exc:
        raise InputError(f"{path}: {exc}") from None
