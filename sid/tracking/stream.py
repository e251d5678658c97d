"""Pipeline -> trackers, frame after frame: people and groups with stable ids from a stream of frames.

``PeopleStream.update(frame, robot_pose)`` runs the stateless per-frame pipeline (``sid.perception.pipeline``) and
feeds its result to the people and group trackers (``sid.tracking.session``) with the camera's view of the frame
(``sid.tracking.view.pipeline_view``). It is the part of ``sid.stream.SocialStream`` before the costmap, and what
``sid detect`` runs on its own (``update_posed``: the frame's pose stage already run, ahead in a worker thread), so
neither imports the costmap for it.

Errors (``TrackingError``, raised before the stages after the pose run, nothing changed): a frame not after the last
one in time, a non-finite timestamp, a robot pose that is not a finite ``RobotPose``. Resets are the session's.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from sid.perception.frame import Frame
from sid.perception.pipeline import FrameResult, Pipeline, PosedFrame
from sid.perception.robot_pose import RobotPose
from sid.tracking.session import SessionUpdate, TrackingParams, TrackingSession
from sid.tracking.view import ViewCone, pipeline_view

__all__ = ["PeopleStream", "TrackedFrame"]


@dataclass
class TrackedFrame:
    """One frame through the pipeline and the trackers: the pipeline's ``result`` (the frame's own detections,
    people and groups) and the trackers' ``tracks`` after it (confirmed people and groups, reset, timing)."""

    result: FrameResult
    tracks: SessionUpdate


class PeopleStream:
    """The per-frame pipeline, then the people and group trackers (``params``). State lives between calls."""

    def __init__(self, pipeline: Pipeline, params: TrackingParams | None = None) -> None:
        self.pipeline = pipeline
        self.tracking = TrackingSession(params, pipeline.group_params)

    def reset(self) -> None:
        """Forget every track and group (ids keep counting up)."""
        self.tracking.reset()

    def update(self, frame: Frame, robot_pose: RobotPose | None = None) -> TrackedFrame:
        """One frame: the whole pipeline, then the trackers. ``robot_pose``: base_footprint in the map at the frame's
        time (None: ``frame.robot_pose``)."""
        pose = frame.robot_pose if robot_pose is None else robot_pose
        self._check(frame, pose)
        if pose is not frame.robot_pose:
            frame = dataclasses.replace(frame, robot_pose=pose)
        return self._track(frame, self.pipeline(frame))

    def update_posed(self, posed: PosedFrame) -> TrackedFrame:
        """One frame whose pose stage has run (``Pipeline.pose_frame``): the stages after it, then the trackers."""
        self._check(posed.frame, posed.frame.robot_pose)
        return self._track(posed.frame, self.pipeline.locate(posed))

    def view(self, frame: Frame) -> ViewCone:
        """The colour camera's field of view on the ground at ``frame`` (``sid.tracking.view.pipeline_view``)."""
        return pipeline_view(frame, self.pipeline)

    def _check(self, frame: Frame, pose: RobotPose | None) -> None:
        self.tracking.check(frame.timestamp, pose, f"frame {frame.index}")

    def _track(self, frame: Frame, result: FrameResult) -> TrackedFrame:
        return TrackedFrame(result, self.tracking.update(result, self.view(frame)))
