"""SocialStream: the pipeline, the trackers and the costmap frame after frame; resets and refusals."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from costmap.grid import LETHAL, GridSpec
from costmap.plugins import CostmapParams, layered_costmap
from sid.perception.frame import Frame
from sid.perception.groups import detect_groups
from sid.perception.people import Person
from sid.perception.pipeline import FrameResult, Pipeline
from sid.perception.robot_pose import BASE_FRAME, MAP_FRAME, RobotPose
from sid.stream import SocialStream
from sid.synthetic.sensor import d435i_calibration
from sid.tracking import TrackingError, TrackingParams

SPEC = GridSpec.from_size(0.05, (-2.0, -5.0), (12.0, 10.0))
CALIBRATION = d435i_calibration(registered=True)
DT = 1 / 15


class ScriptedPipeline(Pipeline):
    """A pipeline whose people (in base_footprint) come from a script of the frame's time, moved into the map when
    the frame has a robot pose, as the real pipeline does."""

    def __init__(self, script: Callable[[float], list[Person]]) -> None:
        super().__init__(pose=lambda frame: [])
        self.script = script

    def __call__(self, frame: Frame) -> FrameResult:
        people = self.script(frame.timestamp)
        pose = frame.robot_pose
        if pose is not None:
            people = [pose.person_to_map(p) for p in people]
        frame_id = BASE_FRAME if pose is None else MAP_FRAME
        timing = {"pose": 0.0, "lift": 0.0, "group": 0.0, "total": 0.0}
        return FrameResult(frame.index, frame.timestamp, [], people, detect_groups(people), timing, frame_id, pose)


def _pair(t: float) -> list[Person]:
    """Two people 3 m ahead facing each other, 0.8 m apart (base_footprint)."""
    return [Person(0, 3.0, 0.4, -math.pi / 2), Person(1, 3.0, -0.4, math.pi / 2)]


def _frame(index: int, pose: RobotPose | None = None, time: float | None = None) -> Frame:
    color = np.zeros((CALIBRATION.color.height, CALIBRATION.color.width, 3), dtype=np.uint8)
    depth = np.zeros((CALIBRATION.color.height, CALIBRATION.color.width), dtype=np.float32)
    timestamp = index * DT if time is None else time
    return Frame(index, color, depth, CALIBRATION, timestamp, robot_pose=pose)


def _cell(x: float, y: float) -> tuple[int, int]:
    (row, col) = SPEC.world_to_cell(np.array([x, y]))[0]
    return int(row), int(col)


def test_people_groups_and_costmap_follow_the_frames_in_the_map() -> None:
    stream = SocialStream(ScriptedPipeline(_pair), SPEC)
    pose = RobotPose(1.0, 0.0, math.pi / 2)  # people 3 m ahead of the robot: at (1.0, 3.0) +- 0.4 in x
    updates = [stream.update(_frame(k, pose)) for k in range(10)]  # a group needs settled tracks: ~0.6 s
    last = updates[-1]
    assert last.frame_id == MAP_FRAME and last.timestamp == pytest.approx(9 * DT)
    assert sorted((round(p.x, 3), round(p.y, 3)) for p in last.people) == [(0.6, 3.0), (1.4, 3.0)]
    assert {p.id for p in last.people} == {p.id for p in updates[3].people}
    assert all(p.state == "standing" for p in last.people)
    (group,) = last.groups
    assert group.kind == "conversation" and group.members == tuple(sorted(p.id for p in last.people))
    master = last.costmap.costs
    assert master[_cell(0.6, 3.0)] == LETHAL and master[_cell(1.0, 3.0)] >= 240
    assert last.result.frame_id == MAP_FRAME and len(last.result.people) == 2
    assert {"pose", "lift", "group", "track", "track_groups", "costmap", "total"} <= last.timing_ms.keys()
    assert updates[0].people == [] and updates[0].reset is None


def test_the_pose_argument_overrides_the_frames_pose() -> None:
    stream = SocialStream(ScriptedPipeline(_pair), SPEC)
    given = RobotPose(0.0, 0.0, 0.0)
    for k in range(4):
        update = stream.update(_frame(k, RobotPose(5.0, 0.0, 0.0)), given)
    assert sorted(round(p.x, 3) for p in update.people) == [3.0, 3.0]


def test_without_a_pose_the_stream_reports_in_base_footprint() -> None:
    stream = SocialStream(ScriptedPipeline(_pair), SPEC)
    for k in range(4):
        update = stream.update(_frame(k))
    assert update.frame_id == BASE_FRAME and len(update.people) == 2


def test_a_frame_out_of_time_order_is_refused_and_changes_nothing() -> None:
    stream = SocialStream(ScriptedPipeline(_pair), SPEC)
    for k in range(4):
        before = stream.update(_frame(k))
    for bad in (before.timestamp, before.timestamp - 1.0):
        with pytest.raises(TrackingError, match="timestamp"):
            stream.update(_frame(9, time=bad))
    with pytest.raises(ValueError, match="frame: timestamp must be a finite number"):  # refused by the record itself
        _frame(9, time=math.nan)
    after = stream.update(_frame(4))
    assert {p.id for p in after.people} == {p.id for p in before.people} and after.reset is None


def test_a_pose_that_is_not_a_finite_robot_pose_is_refused() -> None:
    stream = SocialStream(ScriptedPipeline(_pair), SPEC)
    with pytest.raises(ValueError, match="robot pose: x must be a finite number"):
        RobotPose(math.nan, 0.0, 0.0)
    broken = RobotPose(0.0, 0.0, 0.0)
    object.__setattr__(broken, "yaw", math.nan)  # built around the record's own check
    with pytest.raises(TrackingError, match="robot pose: yaw must be a finite number"):
        stream.update(_frame(0), broken)
    with pytest.raises(TrackingError, match="must be a RobotPose, got tuple"):
        stream.update(_frame(0), (0.0, 0.0, 0.0))  # type: ignore[arg-type]


def test_a_jump_of_the_robot_pose_resets_the_tracks() -> None:
    stream = SocialStream(ScriptedPipeline(_pair), SPEC, params=TrackingParams(max_robot_speed=2.0, jump_tolerance=0.3))
    for k in range(4):
        before = stream.update(_frame(k, RobotPose(0.05 * k, 0.0, 0.0)))  # 0.75 m/s: no jump
    assert before.reset is None and len(before.people) == 2
    jumped = stream.update(_frame(4, RobotPose(3.0, 0.0, 0.0)))
    assert jumped.reset is not None and "jumped 2.85 m" in jumped.reset
    assert jumped.people == [] and jumped.groups == []
    for k in range(5, 8):
        after = stream.update(_frame(k, RobotPose(3.0, 0.0, 0.0)))
    assert min(p.id for p in after.people) > max(p.id for p in before.people)
    turned = stream.update(_frame(8, RobotPose(3.0, 0.0, 2.0)))
    assert turned.reset is not None and "turned 2.00 rad" in turned.reset


def test_losing_the_pose_resets_the_tracks() -> None:
    stream = SocialStream(ScriptedPipeline(_pair), SPEC)
    for k in range(4):
        stream.update(_frame(k, RobotPose(0.0, 0.0, 0.0)))
    update = stream.update(_frame(4))
    assert update.reset is not None and "from the map frame to the base_footprint frame" in update.reset


def test_empty_frames_keep_the_tracks_for_a_while() -> None:
    people: dict[str, list[Person]] = {"now": _pair(0.0)}
    stream = SocialStream(ScriptedPipeline(lambda t: people["now"]), SPEC)
    for k in range(10):
        before = stream.update(_frame(k))
    people["now"] = []
    update = stream.update(_frame(10))
    assert {p.id for p in update.people} == {p.id for p in before.people}
    assert not any(p.visible for p in update.people) and update.groups
    assert update.costmap.costs[_cell(3.0, 0.4)] == LETHAL


def test_an_update_keeps_its_own_costmap_when_later_frames_change_the_stream() -> None:
    people: dict[str, list[Person]] = {"now": _pair(0.0)}
    stream = SocialStream(ScriptedPipeline(lambda t: people["now"]), SPEC)
    kept = [stream.update(_frame(k)) for k in range(10)][-1]
    drawn = kept.costmap.costs.copy()
    assert drawn[_cell(3.0, 0.4)] == LETHAL
    people["now"] = []
    for k in range(10, 60):  # 5 s without anyone: the tracks end and the live costmap empties
        last = stream.update(_frame(k))
    assert not last.people and last.costmap.costs[_cell(3.0, 0.4)] != LETHAL
    np.testing.assert_array_equal(kept.costmap.costs, drawn)


def test_a_ready_costmap_with_the_social_layer_draws_the_tracks() -> None:
    layered = layered_costmap(SPEC, CostmapParams(plugins=("social",)))
    stream = SocialStream(ScriptedPipeline(_pair), layered)
    for k in range(10):
        stream.update(_frame(k))
    assert stream.costmap is layered and layered.master.costs[_cell(3.0, 0.0)] >= 240
    with pytest.raises(ValueError, match="costmap_params only apply"):
        SocialStream(ScriptedPipeline(_pair), layered, CostmapParams())


def test_a_rendered_conversation_is_tracked_through_the_real_pipeline() -> None:
    from sid.sources.synthetic import SyntheticSource
    from sid.synthetic.pose import TruthPose

    source = SyntheticSource("S1", frames=12, fps=15, shaded_color=False)
    spec = GridSpec.from_size(0.05, (-0.5, -3.5), (7.5, 7.0))
    stream = SocialStream(Pipeline(TruthPose(), source.scene.mount), spec)
    updates = [stream.update(frame) for frame in source]
    ids = [{p.id for p in u.people} for u in updates[2:]]
    assert all(i == ids[0] for i in ids) and len(ids[0]) == 2
    (group,) = updates[-1].groups
    assert group.kind == "conversation"
    truth = source[11].truth
    (true_group,) = truth.groups
    assert np.hypot(*np.subtract(group.interest_point, true_group.interest_point)) < 0.15


def test_a_person_missed_for_longer_than_the_report_timeout_is_held_and_still_drawn() -> None:
    people: dict[str, list[Person]] = {"now": [Person(0, 3.0, 0.0, math.pi)]}  # alone, 3 m ahead, in plain view
    stream = SocialStream(ScriptedPipeline(lambda t: people["now"]), SPEC, params=TrackingParams(report_timeout=0.4))
    for k in range(10):
        before = stream.update(_frame(k))
    (track,) = before.people
    people["now"] = []
    missed = [stream.update(_frame(k)) for k in range(10, 20)]  # missed for 1/15 to 10/15 s
    reported = [update for update in missed if update.people]
    assert len(reported) == 6 and all(u.people[0].id == track.id and u.held == [] for u in reported)  # <= 0.4 s
    for update in missed[6:]:
        assert update.people == [] and [p.id for p in update.held] == [track.id]
        assert update.held[0].missed_in_view > 0.4
        assert update.costmap.costs[_cell(3.0, 0.0)] == LETHAL  # the costmap keeps their space
    people["now"] = [Person(0, 3.0, 0.0, math.pi)]
    back = stream.update(_frame(20))
    assert [p.id for p in back.people] == [track.id] and back.held == [] and back.people[0].missed_in_view == 0.0
