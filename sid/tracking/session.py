"""People and groups tracked over a stream of per-frame results, with the resets a moving robot needs.

``TrackingSession.update(result, view)`` feeds one ``FrameResult`` (``sid.perception.pipeline``) to the people
tracker and its tracks to the group tracker. Resets (documented, not errors): both trackers forget everything,
and ``SessionUpdate.reset`` says why, when the robot pose jumps (moves faster than ``max_robot_speed`` or turns
faster than ``max_turn_rate``, plus a tolerance: a relocalisation puts every track in the wrong place), when the
frame the results are given in changes (a pose that appears or disappears), or when time goes back more than
``max_time_back`` (a looped recording, a clock reset, or the frame after one stamped in the future: refused for
good, every later frame would be). Reported (``SessionUpdate.people``, ``groups``): a confirmed track while detected
or missed in the camera's view for at most ``report_timeout``, a confirmed group while one of its members is, and
its members with it; the others are held (``SessionUpdate.held``, ``held_groups``): kept by the trackers until their
timeouts, still drawn on the costmap, but not claimed as present (a track coasting on after its person left).
Errors (``TrackingError``, nothing changed): a result not after the last one in time (but within ``max_time_back`` of
it), a non-finite timestamp or robot pose.
"""

from __future__ import annotations

import math
import time
from collections.abc import Collection, Sequence
from dataclasses import dataclass, field

from sid.checks import check_numbers, is_real
from sid.perception.groups import GroupParams
from sid.perception.people import Person
from sid.perception.pipeline import FrameResult
from sid.perception.robot_pose import RobotPose
from sid.tracking.groups import GroupTracker, GroupTrackerParams
from sid.tracking.records import TIME_TOLERANCE, TrackedGroup, TrackedPerson, Tracks
from sid.tracking.tracker import PeopleTracker, TrackerParams, TrackingError, check_people, check_time_order
from sid.tracking.view import View

__all__ = ["SessionUpdate", "TrackingParams", "TrackingSession", "split_reported"]


@dataclass(frozen=True)
class TrackingParams:
    """The two trackers' parameters, what counts as a jump of the robot pose: it moves more than
    ``max_robot_speed`` (m/s) x dt + ``jump_tolerance`` (m), or turns more than ``max_turn_rate`` (rad/s) x dt +
    ``yaw_tolerance`` (rad), between consecutive frames dt seconds apart, and of time: a frame more than
    ``max_time_back`` (s) before the last one starts the trackers over (one less before it is refused).
    ``report_timeout`` (s): how long a confirmed track missed in the camera's view is still reported
    (``split_reported``; the tracker keeps it until its own ``timeout``)."""

    tracker: TrackerParams = field(default_factory=TrackerParams)
    groups: GroupTrackerParams = field(default_factory=GroupTrackerParams)
    max_robot_speed: float = 2.0
    jump_tolerance: float = 0.3
    max_turn_rate: float = 3.0
    yaw_tolerance: float = 0.3
    max_time_back: float = 1.0
    report_timeout: float = 0.4

    def __post_init__(self) -> None:
        names = (
            "max_robot_speed",
            "jump_tolerance",
            "max_turn_rate",
            "yaw_tolerance",
            "max_time_back",
            "report_timeout",
        )
        check_numbers("tracking", self, names, low=0)


@dataclass
class SessionUpdate:
    """The people and groups reported after one result, why the trackers were reset at it (None: they were not), the
    time (ms) the two trackers took ("track", "track_groups"), and the confirmed tracks and groups held but not
    reported (``split_reported``). Every member of a group reported is among ``people``, of a group held among
    ``held``."""

    people: list[TrackedPerson]
    groups: list[TrackedGroup]
    reset: str | None
    timing_ms: dict[str, float]
    held: list[TrackedPerson] = field(default_factory=list)
    held_groups: list[TrackedGroup] = field(default_factory=list)

    def all_tracks(self) -> Tracks:
        """Every confirmed track and group, reported and held: what the tracked-people layer draws (a person the
        detector has missed for a moment still gets their space on the costmap)."""
        return Tracks([*self.people, *self.held], [*self.groups, *self.held_groups])


class TrackingSession:
    """People and group trackers over consecutive ``FrameResult``s. State lives between calls."""

    def __init__(self, params: TrackingParams | None = None, group_params: GroupParams | None = None) -> None:
        self.params = params or TrackingParams()
        self.people = PeopleTracker(self.params.tracker)
        self.groups = GroupTracker(self.params.groups, group_params)
        self._last: tuple[float, str, RobotPose | None] | None = None  # timestamp, frame id and pose of the last

    def reset(self) -> None:
        """Forget every track and group (ids keep counting up) and the last frame."""
        self.people.reset()
        self.groups.reset()
        self._last = None

    def check(self, timestamp: float, pose: RobotPose | None, what: str = "frame") -> None:
        """Raise TrackingError unless ``timestamp`` (s) is finite and after the last one, and ``pose`` (None allowed)
        a finite RobotPose; ``what`` names the input in the message. A timestamp more than ``max_time_back`` before
        the last one passes: it starts the trackers over."""
        check_time_order(what, timestamp, None if self._last is None or self._rewinds(timestamp) else self._last[0])
        if pose is not None:
            if not isinstance(pose, RobotPose):
                raise TrackingError(f"{what}: robot_pose must be a RobotPose, got {type(pose).__name__}")
            check_numbers(f"{what}: robot pose", pose, ("x", "y", "yaw"), error=TrackingError)

    def update(self, result: FrameResult, view: View | None = None) -> SessionUpdate:
        """Track the people and groups of ``result``; ``view``: the camera's field of view in ``result.frame_id``
        (None: everything counts as in view)."""
        self.check(result.timestamp, result.robot_pose, f"frame {result.frame}")
        reset = self._rewind_reason(result.timestamp) or self._reset_reason(result)
        if reset is not None:
            check_people(result.people)  # bad people refuse the frame before the reset forgets the tracks
            self.people.reset()
            self.groups.reset()
        update = self._track(result.people, result.timestamp, view)  # a TrackingError here keeps the last frame
        self._last = (result.timestamp, result.frame_id, result.robot_pose)
        update.reset = reset
        return update

    def track(self, people: Sequence[Person], timestamp: float, view: View | None = None) -> SessionUpdate:
        """Track detected ``people`` given in one fixed ground frame at ``timestamp`` (s), with no robot pose to
        check (``sid track``, ``sid eval crowd``). ``view``: where the detector looked (None: everywhere)."""
        self.check(timestamp, None)
        reset = self._rewind_reason(timestamp)
        if reset is not None:
            check_people(people)  # bad people refuse the frame before the reset forgets the tracks
            self.people.reset()
            self.groups.reset()
        update = self._track(people, timestamp, view)  # a TrackingError here (bad people) changes nothing
        self._last = (timestamp, "ground", None)
        update.reset = reset
        return update

    def _rewinds(self, timestamp: float) -> bool:
        """Whether ``timestamp`` (s) lies more than ``max_time_back`` before the last frame's."""
        return self._last is not None and is_real(timestamp) and timestamp < self._last[0] - self.params.max_time_back

    def _rewind_reason(self, timestamp: float) -> str | None:
        if self._last is None or not self._rewinds(timestamp):
            return None
        return f"time went back {self._last[0] - timestamp:.3g} s"

    def _track(self, people: Sequence[Person], timestamp: float, view: View | None) -> SessionUpdate:
        t0 = time.perf_counter()
        tracked = self.people.update(people, timestamp, view)
        t1 = time.perf_counter()
        groups = self.groups.update(tracked, timestamp)
        t2 = time.perf_counter()
        reported, held, kept = split_reported(tracked, [g.members for g in groups], self.params.report_timeout)
        update = SessionUpdate(reported, [], None, {"track": (t1 - t0) * 1e3, "track_groups": (t2 - t1) * 1e3}, held)
        for group, keep in zip(groups, kept, strict=True):
            (update.groups if keep else update.held_groups).append(group)
        return update

    def _reset_reason(self, result: FrameResult) -> str | None:
        """Why the tracks no longer hold at this result (None: they do)."""
        if self._last is None:
            return None
        last_time, last_frame_id, last_pose = self._last
        if result.frame_id != last_frame_id:
            return f"positions changed from the {last_frame_id} frame to the {result.frame_id} frame"
        pose = result.robot_pose
        if pose is None or last_pose is None:
            return None
        p, dt = self.params, result.timestamp - last_time
        moved = math.hypot(pose.x - last_pose.x, pose.y - last_pose.y)
        turned = abs(math.remainder(pose.yaw - last_pose.yaw, math.tau))
        if moved > p.max_robot_speed * dt + p.jump_tolerance:
            return f"the robot pose jumped {moved:.2f} m in {dt:.3f} s"
        if turned > p.max_turn_rate * dt + p.yaw_tolerance:
            return f"the robot pose turned {turned:.2f} rad in {dt:.3f} s"
        return None


def split_reported(
    people: Sequence[TrackedPerson], groups: Sequence[Collection[int]], report_timeout: float
) -> tuple[list[TrackedPerson], list[TrackedPerson], list[bool]]:
    """The confirmed tracks ``people`` split into those reported and those held, and which of ``groups`` (member
    ids) are reported. A track is fresh while it was missed in the camera's view for at most ``report_timeout`` (s;
    ``TrackedPerson.missed_in_view``); a group is reported while one of its members is fresh, and a track while it is
    fresh or a member of a group reported (a group holds its members through their misses). Held tracks, and groups
    whose members all went unseen, coast on the trackers' predictions where the detector, looking there, sees nobody:
    mostly people who left."""
    limit = report_timeout + TIME_TOLERANCE
    fresh = {p.id for p in people if p.missed_in_view <= limit}
    kept = [any(i in fresh for i in group) for group in groups]
    grouped = {i for group, keep in zip(groups, kept, strict=True) if keep for i in group}
    reported: list[TrackedPerson] = []
    held: list[TrackedPerson] = []
    for person in people:
        (reported if person.id in fresh or person.id in grouped else held).append(person)
    return reported, held, kept
