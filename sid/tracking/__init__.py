"""People and groups over time: a ground-plane multi-person tracker and a group tracker on its tracks.

- ``records``: ``TrackedPerson``, ``TrackedGroup`` and ``Tracks`` (both at one frame), what the trackers report.
- ``motion``: the constant-velocity Kalman filter, stepped for all tracks at once.
- ``view``: where the detector looks on the ground (``ViewCone``, a camera; ``ViewRegion``, a fixed area).
- ``tracker``: ``PeopleTracker`` (stable ids, confirmation, timeouts, smoothed facing, standing / walking).
- ``groups``: ``GroupTracker`` (stable group ids, hysteresis, walking groups that are never an o-space).
- ``coherent``: ``CoherentMotion``, the classical walking-group reference the group tracker is measured against.
- ``session``: ``TrackingSession``, both trackers over the pipeline's per-frame results, with resets on pose jumps.
- ``stream``: ``PeopleStream``, the per-frame pipeline then both trackers, frame after frame (``sid detect``).

Use ``sid.stream.SocialStream`` to run them with the pipeline and the costmap; docs/tracking.md has the measurements.
"""

from sid.tracking.groups import GroupTracker, GroupTrackerParams
from sid.tracking.records import GroupKind, MotionState, TrackedGroup, TrackedPerson, Tracks
from sid.tracking.session import SessionUpdate, TrackingParams, TrackingSession
from sid.tracking.stream import PeopleStream, TrackedFrame
from sid.tracking.tracker import PeopleTracker, TrackerParams, TrackingError
from sid.tracking.view import View, ViewCone, ViewRegion, camera_fov, camera_view_cone, pipeline_view, scene_view

__all__ = [
    "GroupKind",
    "GroupTracker",
    "GroupTrackerParams",
    "MotionState",
    "PeopleStream",
    "PeopleTracker",
    "SessionUpdate",
    "TrackedFrame",
    "TrackedGroup",
    "TrackedPerson",
    "TrackerParams",
    "TrackingError",
    "TrackingParams",
    "TrackingSession",
    "Tracks",
    "View",
    "ViewCone",
    "ViewRegion",
    "camera_fov",
    "camera_view_cone",
    "pipeline_view",
    "scene_view",
]
