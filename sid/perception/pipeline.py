"""One frame through the paper's pipeline: pose -> 3D people -> groups, with per-stage timing.

Stages: ``pose`` (the pose model, or ``TruthPose`` on synthetic frames), ``lift`` (keypoint depth, 3D keypoints,
world positions and facing directions; depth is looked up sparsely at the keypoints, so the full frame is never
aligned) and ``group`` (the paper's Algorithm 1). Outputs are in the map frame when the frame carries the robot's
pose (``Frame.robot_pose``), else in ``base_footprint`` (through ``sid.perception.mount``); ``FrameResult.frame_id``
says which (``sid.perception.robot_pose``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sid.perception.frame import Frame
from sid.perception.group import Group, group_json
from sid.perception.groups import GroupParams, detect_groups
from sid.perception.keypoints import PoseDetection
from sid.perception.lifting import LiftParams, lift_people
from sid.perception.mount import CameraMount
from sid.perception.people import Person
from sid.perception.robot_pose import BASE_FRAME, MAP_FRAME, RobotPose

__all__ = ["FrameResult", "Pipeline", "PoseFn", "PosedFrame", "image_pose"]

PoseFn = Callable[[Frame], list[PoseDetection]]


def image_pose(estimator: Callable[[np.ndarray], list[PoseDetection]]) -> PoseFn:
    """Adapt an image pose estimator (``sid.perception.pose``) to the pipeline, which hands it whole frames."""

    def run(frame: Frame) -> list[PoseDetection]:
        return estimator(frame.color)

    return run


@dataclass
class FrameResult:
    """What the pipeline found in one frame and how long each stage took (ms).

    people and groups (positions and keypoints in metres, facings in radians) are in ``frame_id``: ``"map"`` when
    the robot's pose was known (``robot_pose``, base_footprint in the map), else ``"base_footprint"``. timing_ms:
    "pose", "lift", "group" and "total", their sum (the frame's work; its latency too unless the pose ran ahead in
    another thread).
    """

    frame: int
    timestamp: float
    detections: list[PoseDetection]
    people: list[Person]
    groups: list[Group]
    timing_ms: dict[str, float] = field(default_factory=dict)
    frame_id: str = BASE_FRAME
    robot_pose: RobotPose | None = None

    def to_json(self, keypoints: bool = True) -> dict[str, Any]:
        """The JSON-lines record of ``sid detect``."""
        pose = self.robot_pose
        return {
            "frame": self.frame,
            "timestamp": self.timestamp,
            "frame_id": self.frame_id,
            "robot_pose": None if pose is None else {"x": pose.x, "y": pose.y, "yaw": pose.yaw},
            "people": [_person_json(p, keypoints) for p in self.people],
            "groups": [group_json(g) for g in self.groups],
            "timing_ms": {k: round(v, 3) for k, v in self.timing_ms.items()},
        }


def _person_json(person: Person, keypoints: bool) -> dict[str, Any]:
    record: dict[str, Any] = {
        "id": int(person.id),
        "x": round(float(person.x), 4),
        "y": round(float(person.y), 4),
        "theta": None if person.theta is None else round(float(person.theta), 4),
        "orientation_quality": round(float(person.orientation_quality), 3),
    }
    if keypoints:
        kps = person.keypoints_world
        record["keypoints"] = None if kps is None else _keypoints_json(kps)
    return record


def _keypoints_json(keypoints: np.ndarray) -> list[list[float] | None]:
    """(17, 3) keypoints (m) -> rows rounded to 0.1 mm, None where a keypoint is missing (NaN). One np.round per
    person rather than round() per value (docs/benchmarks.md, "Start-up and the detect loop"): the same digits except
    for values within a rounding error of a half (np.round scales, then rounds half to even)."""
    missing = np.isnan(keypoints).any(axis=1).tolist()
    return [None if gone else row for row, gone in zip(np.round(keypoints, 4).tolist(), missing, strict=True)]


@dataclass(frozen=True)
class PosedFrame:
    """A frame after the pose stage: its detections (colour-image pixels) and how long the stage took (ms)."""

    frame: Frame
    detections: list[PoseDetection]
    pose_ms: float


@dataclass
class Pipeline:
    """Pose -> people -> groups for one frame at a time, in the map when the frame has a robot pose (else in
    base_footprint). Stateless between frames.

    ``pipeline(frame)`` runs both halves; ``pose_frame`` and ``locate`` run them apart, e.g. the pose of the next
    frame in a worker thread while this thread lifts and groups the last one (``sid detect`` with ``sid.ahead``).
    """

    pose: PoseFn
    mount: CameraMount = field(default_factory=CameraMount)
    lift_params: LiftParams = field(default_factory=LiftParams)
    group_params: GroupParams = field(default_factory=GroupParams)
    group: bool = True
    """False: skip the group stage (``groups`` empty, no "group" timing), e.g. when a tracker groups the tracks."""

    def __call__(self, frame: Frame) -> FrameResult:
        return self.locate(self.pose_frame(frame))

    def pose_frame(self, frame: Frame) -> PosedFrame:
        """The pose stage: the frame's 2D detections."""
        start = time.perf_counter()
        detections = self.pose(frame)
        return PosedFrame(frame, detections, (time.perf_counter() - start) * 1e3)

    def locate(self, posed: PosedFrame) -> FrameResult:
        """The stages after the pose: people in 3D (lift) and their groups."""
        frame = posed.frame
        t1 = time.perf_counter()
        people = lift_people(posed.detections, frame.depth, frame.calibration, self.mount, self.lift_params)
        pose = frame.robot_pose
        if pose is not None:
            people = [pose.person_to_map(p) for p in people]
        t2 = time.perf_counter()
        groups = detect_groups(people, self.group_params) if self.group else []
        t3 = time.perf_counter()
        timing = {"pose": posed.pose_ms, "lift": (t2 - t1) * 1e3} | ({"group": (t3 - t2) * 1e3} if self.group else {})
        return FrameResult(
            frame.index,
            frame.timestamp,
            posed.detections,
            people,
            groups,
            timing | {"total": posed.pose_ms + (t3 - t1) * 1e3},
            BASE_FRAME if pose is None else MAP_FRAME,
            pose,
        )
