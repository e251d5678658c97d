"""What a static synthetic scene holds: people standing on the ground, the groups they form, the camera mount and
the background. Frame: the robot's ``base_footprint`` (REP-103/105, ``sid.perception.mount``; with the default mount
the origin is on the ground below the camera), x forward, y left, z up; metres and radians.

Scene files (JSON or YAML) hold ``{"name": ..., "people": [{"x", "y", "theta"[, "id", "height"]}, ...],
"groups": [[id, ...], ...], "camera": {"height": 0.9, "tilt": 0.0}, "wall_distance": 5.0}``; only ``people`` is
required (``yaw`` is accepted for ``theta``). Costmap scenario files (they have a ``robot`` section) describe scenes
in the map frame, possibly moving: ``sid.synthetic.sequence`` reads them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sid.checks import check_numbers, check_yaw
from sid.documents import load_document
from sid.errors import InputError
from sid.perception.mount import CameraMount
from sid.perception.people import Person

__all__ = ["Scene", "ScenePerson"]


@dataclass(frozen=True)
class ScenePerson:
    """A standing person: ground position (x, y) in m, facing yaw theta in rad (CCW from +x), height in m."""

    id: int
    x: float
    y: float
    theta: float
    height: float = 1.70

    def __post_init__(self) -> None:
        check_numbers(f"scene person {self.id}", self, ("x", "y", "theta", "height"))
        check_yaw(f"scene person {self.id}", "theta", self.theta)
        if not 0.5 <= self.height <= 2.5:
            raise InputError(f"scene person {self.id}: height {self.height} m is not a standing person (0.5-2.5 m)")

    def as_person(self) -> Person:
        """The ``sid.perception.people.Person`` record (exact position and facing, orientation quality 1)."""
        return Person(self.id, self.x, self.y, self.theta, 1.0)


@dataclass(frozen=True)
class Scene:
    """People, the groups among them (tuples of person ids), the camera mount and the background wall.

    ``wall_distance``: a wall perpendicular to the world x axis at that distance (m), None for open space (the
    ground plane is always there).
    """

    name: str
    people: tuple[ScenePerson, ...]
    groups: tuple[tuple[int, ...], ...] = ()
    mount: CameraMount = field(default_factory=CameraMount)
    wall_distance: float | None = 5.0

    def __post_init__(self) -> None:
        ids = [p.id for p in self.people]
        if len(set(ids)) != len(ids):
            raise InputError(f"scene {self.name}: person ids must be unique, got {ids}")
        for group in self.groups:
            missing = set(group) - set(ids)
            if missing:
                raise InputError(f"scene {self.name}: group {group} names unknown people {sorted(missing)}")
            if len(group) < 2:
                raise InputError(f"scene {self.name}: a group needs at least two members, got {group}")
        positions = np.array([[p.x, p.y] for p in self.people]).reshape(-1, 2)
        if len(positions) > 1:
            gaps = np.linalg.norm(positions[:, None] - positions[None], axis=-1) + np.eye(len(positions)) * 1e9
            if gaps.min() < 0.3:
                i, j = np.unravel_index(np.argmin(gaps), gaps.shape)
                raise InputError(
                    f"scene {self.name}: people {ids[i]} and {ids[j]} stand {gaps.min():.2f} m apart; bodies "
                    "would overlap (need >= 0.3 m)"
                )
        if self.wall_distance is not None:
            too_far = [p.id for p in self.people if p.x > self.wall_distance - 0.3]
            if too_far:
                raise InputError(f"scene {self.name}: people {too_far} stand in or behind the wall")

    @classmethod
    def from_file(cls, path: str | Path) -> Scene:
        """Read a scene file (.json, or YAML for any other suffix; see the module docstring)."""
        path = Path(path)
        try:
            data = load_document(path)
        except ValueError as exc:
            raise InputError(f"scene {exc}") from None
        try:
            return cls.from_dict(data, default_name=path.stem)
        except ValueError as exc:
            raise InputError(f"scene {path}: {exc}") from None

    @classmethod
    def from_dict(cls, data: Any, default_name: str = "scene") -> Scene:
        """Build a scene from the parsed file content (see the module docstring)."""
        if isinstance(data, dict) and "robot" in data:
            raise InputError("a costmap scenario file (it has a robot): read it with sid.synthetic.sequence")
        if not isinstance(data, dict) or not isinstance(data.get("people"), list) or not data["people"]:
            raise InputError('expected an object with a non-empty "people" list')
        people = tuple(_person(entry, index) for index, entry in enumerate(data["people"]))
        camera = data.get("camera") or {}
        if not isinstance(camera, dict):
            raise InputError('"camera" must be an object with "height" and "tilt"')
        try:
            groups = tuple(tuple(int(i) for i in group) for group in data.get("groups") or ())
            mount = CameraMount(float(camera.get("height", 0.9)), float(camera.get("tilt", 0.0)))
            wall = data.get("wall_distance", 5.0)
            return cls(
                str(data.get("name", default_name)), people, groups, mount, None if wall is None else float(wall)
            )
        except (TypeError, ValueError) as exc:
            raise InputError(str(exc)) from None

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "people": [{"id": p.id, "x": p.x, "y": p.y, "theta": p.theta, "height": p.height} for p in self.people],
            "groups": [list(g) for g in self.groups],
            "camera": {"height": self.mount.height, "tilt": self.mount.tilt},
            "wall_distance": self.wall_distance,
        }


def _person(entry: Any, index: int) -> ScenePerson:
    if not isinstance(entry, dict):
        raise InputError(f"people[{index}] must be an object with x, y, theta")
    theta = entry.get("theta", entry.get("yaw"))
    if theta is None or "x" not in entry or "y" not in entry:
        raise InputError(f"people[{index}] needs x, y and theta (or yaw), got keys {sorted(entry)}")
    try:
        return ScenePerson(
            int(entry.get("id", index)),
            float(entry["x"]),
            float(entry["y"]),
            float(theta),
            float(entry.get("height", 1.70)),
        )
    except (TypeError, ValueError) as exc:
        raise InputError(f"people[{index}]: {exc}") from None
