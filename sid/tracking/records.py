"""What the trackers report: people and groups with identities that last across frames.

Positions and velocities are in the frame the tracker was fed (the map frame when a ``sid.stream.SocialStream``
runs it: REP-103, metres, m/s); yaws in radians, counter-clockwise from +x; times in seconds (frame timestamps).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from sid.errors import InputError
from sid.perception.group import Group, group_json
from sid.perception.people import Person

__all__ = ["TIME_TOLERANCE", "GroupKind", "MotionState", "TrackedGroup", "TrackedPerson", "Tracks", "still_tracks"]

MotionState = Literal["standing", "walking"]
GroupKind = Literal["conversation", "walking"]

TIME_TOLERANCE = 1e-6
"""Seconds within which the trackers take a time difference as equal to a window or timeout: frames a whole number
of periods apart (15 frames at 15 Hz, 1 s) stay so whatever rounding the clock's offset brings (a ROS stamp of
1.7e9 s is rounded to 2.4e-7 s)."""


@dataclass(frozen=True)
class TrackedPerson:
    """One confirmed person track at the current frame.

    id: the track id, never reused by the tracker that made it. (x, y): filtered position (m); (vx, vy): velocity
    (m/s). theta: smoothed facing (rad), None while no facing was ever measured. state: "standing" or "walking"
    (speed with hysteresis, ``TrackerParams``). visible: detected in this frame. in_view: the predicted position
    lies in the camera's field of view (True when the tracker was given no view). last_seen: timestamp (s) of the
    last detection. detection: the id of the person of this frame's input it was matched to (None when missed).
    speed_sigma: standard deviation of the velocity estimate along each axis (m/s; a new track's velocity is
    unknown: ``TrackerParams.initial_speed_sigma``). orientation_quality: the measured facings' orientation quality
    in [0, 1] (``Person.orientation_quality``), averaged as theta is; 0 while theta is None. missed_in_view:
    seconds undetected since the last detection while the camera could see the track (time out of its view or behind
    someone detected nearer to it does not count; 0 when visible), the clock of ``TrackerParams.timeout``.
    """

    id: int
    x: float
    y: float
    vx: float
    vy: float
    theta: float | None
    state: MotionState
    visible: bool
    in_view: bool
    last_seen: float
    detection: int | None
    speed_sigma: float
    orientation_quality: float
    missed_in_view: float = 0.0

    @property
    def speed(self) -> float:
        """|velocity| (m/s)."""
        return math.hypot(self.vx, self.vy)

    @property
    def walking(self) -> bool:
        return self.state == "walking"

    def as_person(self) -> Person:
        """The track as a per-frame ``Person`` (id = track id), its facing with its averaged orientation quality."""
        return Person(self.id, self.x, self.y, self.theta, self.orientation_quality)

    def to_json(self) -> dict[str, Any]:
        """The track as plain JSON (``sid detect``): id, x, y, theta, orientation_quality, velocity [vx, vy], state,
        visible."""
        return {
            "id": self.id,
            "x": round(self.x, 4),
            "y": round(self.y, 4),
            "theta": None if self.theta is None else round(self.theta, 4),
            "orientation_quality": round(self.orientation_quality, 3),
            "velocity": [round(self.vx, 3), round(self.vy, 3)],
            "state": self.state,
            "visible": self.visible,
        }


@dataclass(frozen=True, eq=False)  # compared by identity: ``zone`` is an array
class TrackedGroup:
    """One confirmed group at the current frame.

    id: the group track id, never reused. kind: "conversation" (an o-space: people standing and facing a common
    point, found by ``sid.perception.groups.detect_groups``) or "walking" (people moving together, side by side or
    in file; never an o-space). members: track ids (``TrackedPerson.id``), sorted. interest_point: the o-space centre
    (conversation) or the members' centroid (walking), (x, y) in m. zone: the o-space polygon of the last frame the
    group was detected in, (K, 2) counter-clockwise (empty for walking groups). area (m^2), spread (m): as in
    ``Group``. velocity: the members' mean velocity (m/s). last_seen: timestamp (s) of the last detection.
    """

    id: int
    kind: GroupKind
    members: tuple[int, ...]
    interest_point: tuple[float, float]
    zone: np.ndarray
    area: float
    spread: float
    velocity: tuple[float, float]
    last_seen: float

    def as_group(self) -> Group:
        """The group as a per-frame ``Group`` whose members are track ids."""
        return Group(self.members, self.interest_point, self.area, self.zone, self.spread)

    def to_json(self) -> dict[str, Any]:
        """The group as plain JSON (``sid detect``): id, kind, members (track ids), the geometry of ``sid groups``,
        velocity [vx, vy]."""
        return {
            "id": self.id,
            "kind": self.kind,
            **group_json(self.as_group()),
            "velocity": [round(self.velocity[0], 3), round(self.velocity[1], 3)],
        }


@dataclass(frozen=True)
class Tracks:
    """What the trackers hold at one frame: confirmed people and groups (the costmap's input
    ``costmap.layers.tracked.TRACKS``).

    Every group member must be one of the people; ids are distinct.
    """

    people: Sequence[TrackedPerson] = ()
    groups: Sequence[TrackedGroup] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "people", tuple(self.people))
        object.__setattr__(self, "groups", tuple(self.groups))
        ids = {p.id for p in self.people}
        if len(ids) != len(self.people):
            raise InputError("tracks: a track id appears twice")
        for group in self.groups:
            missing = sorted(set(group.members) - ids)
            if missing:
                raise InputError(f"tracks: group {group.id} has members {missing} that are not among the people")


def still_tracks(people: Sequence[Person], groups: Sequence[Group], timestamp: float = 0.0) -> Tracks:
    """``people`` as standing tracks seen at ``timestamp`` (s), each with its own id, no velocity and its facing at
    full orientation quality, and ``groups`` as conversations (ids from 1): the tracks of a scene at rest, for a
    tracked-people layer drawn from a snapshot (``sid plan``, ``sid costmap``)."""
    tracked = [
        TrackedPerson(p.id, p.x, p.y, 0.0, 0.0, p.theta, "standing", True, True, timestamp, p.id, 0.0,
                      p.orientation_quality)
        for p in people
    ]  # fmt: skip
    conversations = [
        TrackedGroup(k, "conversation", tuple(sorted(g.members)), g.interest_point, g.zone, g.area, g.spread,
                     (0.0, 0.0), timestamp)
        for k, g in enumerate(groups, start=1)
    ]  # fmt: skip
    return Tracks(tracked, conversations)
