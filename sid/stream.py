"""The streaming object: one call per frame keeps people, groups and the social costmap up to date.

``SocialStream.update(frame, robot_pose)`` runs the stateless per-frame pipeline (``sid.perception.pipeline``) and
the people and group trackers (``sid.tracking.stream.PeopleStream``), then the layered costmap (``costmap``) on the
tracks, and returns a ``StreamUpdate``. Positions are in the map frame when a robot pose is known (``robot_pose``, else
``frame.robot_pose``), else in ``base_footprint`` (right only while the robot stands still).

Resets (documented, not errors; ``StreamUpdate.reset`` says why): a jump of the robot pose, or a pose that appears
or disappears (``sid.tracking.session``). Errors (``TrackingError``, raised before the pipeline runs, nothing
changed): a frame not after the last one in time, a non-finite timestamp, a robot pose that is not a finite
``RobotPose``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from costmap.grid import Costmap2D, GridSpec
from costmap.layer import LayerInputs
from costmap.layered import LayeredCostmap
from costmap.layers.obstacle import SCAN
from costmap.layers.social import GROUPS, PEOPLE
from costmap.layers.tracked import TRACKS
from costmap.plugins import CostmapParams, layered_costmap
from costmap.scan import LaserScan
from sid.errors import InputError
from sid.perception.frame import Frame
from sid.perception.pipeline import FrameResult, Pipeline
from sid.perception.robot_pose import RobotPose
from sid.tracking.assignment import load_solver
from sid.tracking.records import TrackedGroup, TrackedPerson
from sid.tracking.session import TrackingParams
from sid.tracking.stream import PeopleStream
from sid.tracking.view import ViewCone

__all__ = ["STREAM_PLUGINS", "SocialStream", "StreamUpdate"]

STREAM_PLUGINS = ("static", "lidar", "tracked_people", "inflation")
"""The layers of the costmap a stream builds from a ``GridSpec``: the tracked-people layer instead of the social one."""


@dataclass
class StreamUpdate:
    """The stream's state after one frame.

    frame_id: the frame of every position ("map" or "base_footprint"). timestamp: the frame's (s). people, groups:
    the tracks and groups reported (``sid.tracking.session.split_reported``; the costmap also draws those held,
    missed for longer than ``TrackingParams.report_timeout``). costmap: the combined grid after
    this frame (``costmap.costs``: uint8, Nav2 values), a copy that later frames leave as it is (the stream's live
    LayeredCostmap is ``SocialStream.costmap``).
    result: the per-frame pipeline's raw result. timing_ms: per stage ("pose", "lift", "group" from the pipeline,
    then "track", "track_groups", "costmap", and "total"). reset: why the trackers were reset at this frame (None:
    they were not). held, held_groups: the confirmed tracks and groups not reported (``SessionUpdate.held``).
    """

    frame_id: str
    timestamp: float
    people: list[TrackedPerson]
    groups: list[TrackedGroup]
    costmap: Costmap2D
    result: FrameResult
    timing_ms: dict[str, float]
    reset: str | None = None
    held: list[TrackedPerson] = field(default_factory=list)
    held_groups: list[TrackedGroup] = field(default_factory=list)


class SocialStream:
    """Pipeline -> trackers -> costmap, frame after frame.

    ``costmap``: a ready ``LayeredCostmap`` (its layers read ``TRACKS``, or ``PEOPLE`` and ``GROUPS``, which
    the stream fills with the tracks: a "social" layer draws tracked people too), or a ``GridSpec`` (in the frame
    of the positions, the map when poses are given) from which one is built with ``costmap_params`` (default:
    ``STREAM_PLUGINS`` with default parameters). ``params``: the trackers' (``sid.tracking.session``).
    The group tracker groups the tracks itself: a pipeline built with ``group=False`` skips the per-frame
    grouping it would otherwise also do (``StreamUpdate.result.groups`` is then empty).
    """

    def __init__(
        self,
        pipeline: Pipeline,
        costmap: LayeredCostmap | GridSpec,
        costmap_params: CostmapParams | None = None,
        params: TrackingParams | None = None,
    ) -> None:
        self.pipeline = pipeline
        if isinstance(costmap, GridSpec):
            costmap = layered_costmap(costmap, costmap_params or CostmapParams(plugins=STREAM_PLUGINS))
        elif costmap_params is not None:
            raise InputError("stream: costmap_params only apply when the costmap is built from a GridSpec")
        self.costmap = costmap
        self.people = PeopleStream(pipeline, params)
        load_solver()  # now, not on the first ambiguous frame: a robot should not pause mid-run for an import

    def reset(self) -> None:
        """Forget every track and group (ids keep counting up); the costmap empties at the next update."""
        self.people.reset()

    def update(self, frame: Frame, robot_pose: RobotPose | None = None, scan: LaserScan | None = None) -> StreamUpdate:
        """One frame: pipeline, trackers, costmap. ``robot_pose``: base_footprint in the map at the frame's time
        (None: ``frame.robot_pose``). ``scan``: a 2D scan for the LiDAR layer, in the costmap's frame."""
        start = time.perf_counter()
        step = self.people.update(frame, robot_pose)
        result, tracked = step.result, step.tracks
        t0 = time.perf_counter()
        tracks = tracked.all_tracks()
        conversations = [g.as_group() for g in tracks.groups if g.kind == "conversation"]
        people = [p.as_person() for p in tracks.people]
        self.costmap.update(LayerInputs({PEOPLE: people, GROUPS: conversations, SCAN: scan, TRACKS: tracks}))
        t1 = time.perf_counter()
        timing = result.timing_ms | tracked.timing_ms | {"costmap": (t1 - t0) * 1e3, "total": (t1 - start) * 1e3}
        return StreamUpdate(
            result.frame_id,
            frame.timestamp,
            tracked.people,
            tracked.groups,
            self.costmap.master.copy(),
            result,
            timing,
            tracked.reset,
            tracked.held,
            tracked.held_groups,
        )

    def view(self, frame: Frame) -> ViewCone:
        """The colour camera's field of view on the ground at ``frame`` (``PeopleStream.view``)."""
        return self.people.view(frame)
