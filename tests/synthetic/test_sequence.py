"""Moving synthetic scenes: people and the robot on scripted paths, frames with the robot's pose, map-frame truth."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from sid.perception.pipeline import Pipeline
from sid.scenario.loader import scenario_from_dict
from sid.sources.synthetic import SyntheticSource
from sid.synthetic.noise import DepthNoise, KeypointNoise
from sid.synthetic.pose import TruthPose
from sid.synthetic.scene import Scene
from sid.synthetic.sensor import SyntheticCamera
from sid.synthetic.sequence import SEQUENCES, SyntheticSequence, builtin_sequence


def _sequence(people: list[dict], conversations: Any = (), robot: dict | None = None) -> SyntheticSequence:
    data = {
        "map": {"resolution": 0.1, "origin": [-2.0, -6.0], "size": [12.0, 12.0]},
        "robot": robot or {"start": [0.0, 0.0, 0.0], "goal": [5.0, 0.0]},
        "people": people,
        "conversations": list(conversations),
    }
    return SyntheticSequence.from_scenario(scenario_from_dict(data, default_name="test"))


def _exact(scene: SyntheticSequence | str, **options: Any) -> SyntheticSource:
    return SyntheticSource(scene, noise=DepthNoise.exact(), keypoint_noise=KeypointNoise(0.0, 0.0), **options)


def test_a_conversation_holds_while_all_its_members_stand() -> None:
    sequence = _sequence(
        [
            {"id": 1, "x": 3.0, "y": 0.4, "theta": -1.5708},
            {"id": 2, "x": 3.0, "y": -0.4, "theta": 1.5708, "path": [[3.0, -3.0]], "start_time": 2.0},
        ],
        [[1, 2]],
    )
    assert sequence.at(1.9).groups == ((1, 2),)
    leaving = sequence.at(3.0)
    assert leaving.groups == () and leaving.states[2].moving and not leaving.states[1].moving
    assert (leaving.states[2].vx, leaving.states[2].vy) == pytest.approx((0.0, -1.2))
    source = _exact(sequence, shaded_color=False)
    assert [g.members for g in source[57].truth.groups] == [(1, 2)] and source[57].truth.groups[0].detectable
    late = source[90].truth  # t = 3 s
    assert late.groups == [] and [p.walking for p in late.people] == [False, True]
    assert (late.people[1].vx, late.people[1].vy) == pytest.approx((0.0, -1.2))


def test_a_walker_hides_a_standing_person_from_the_camera() -> None:
    sequence = _sequence(
        [
            {"id": 1, "x": 4.0, "y": 0.0, "theta": math.pi},
            {"id": 2, "x": 1.5, "y": 2.5, "path": [[1.5, -2.5]], "speed": 1.0},
        ]
    )
    source = _exact(sequence, shaded_color=False)
    before, during = source[0], source[75]  # t = 0 s (walker outside the view) and 2.5 s (straight in front)
    assert before.truth.people[0].visible.all() and before.truth.people[0].in_view
    assert not before.truth.people[1].in_view and not before.truth.people[1].visible.any()
    standing, walker = during.truth.people
    assert walker.walking and walker.in_view and (walker.x, walker.y) == pytest.approx((1.5, 0.0))
    assert (
        not standing.visible.any()
        and not standing.in_view
        and standing.keypoints_px[0] == pytest.approx(before.truth.people[0].keypoints_px[0])
    )  # in the image, behind the walker
    assert 0 < np.count_nonzero(source[72].truth.people[0].visible) < 17  # half hidden 0.1 s earlier
    detections = TruthPose()(during)
    assert len(detections) == 1  # the hidden person has too few observed keypoints to be detected
    assert len(TruthPose()(before)) == 1  # and the walker was out of view at the start


def test_frames_carry_the_robot_pose_and_the_pipeline_reports_in_the_map() -> None:
    source = _exact("drive_past_group", shaded_color=False)
    sequence = source.scene
    assert isinstance(sequence, SyntheticSequence) and len(source) == 421  # 14 s at 30 fps, both ends included
    pipeline = Pipeline(TruthPose())
    (true_group,) = builtin_sequence("drive_past_group").conversations
    for index in (0, 45, 90):  # the whole group in view (person 1 leaves it after about 3.5 s)
        frame = source[index]
        assert frame.timestamp == pytest.approx(index / 30)
        assert frame.robot_pose is not None and frame.truth.frame_id == "map"
        travelled = 0.5 * frame.timestamp
        assert (frame.robot_pose.x, frame.robot_pose.y) == pytest.approx((0.8 * travelled, 0.6 * travelled))
        assert frame.robot_pose.yaw == pytest.approx(math.atan2(0.6, 0.8))
        assert [(p.x, p.y) for p in frame.truth.people] == [(2.452, 4.257), (3.375, 3.611), (3.473, 4.732)]
        result = pipeline(frame)
        assert result.frame_id == "map" and len(result.people) == 3
        for person in result.people:
            nearest = min(math.hypot(person.x - t.x, person.y - t.y) for t in frame.truth.people)
            assert nearest < 0.1
        (group,) = result.groups
        (truth_group,) = frame.truth.groups
        assert len(group.members) == 3 and truth_group.members == true_group
        assert math.dist(group.interest_point, truth_group.interest_point) < 0.15
    last = source[len(source) - 1]
    assert last.robot_pose is not None and (last.robot_pose.x, last.robot_pose.y) == pytest.approx((5.6, 4.2))
    assert not any(p.in_view for p in last.truth.people)  # driven past: the group is behind the camera


def test_frames_rendered_in_order_equal_frames_rendered_alone() -> None:
    walking = SyntheticSource("crossing_walkers", seed=3)  # walker 6 starts at t = 1 s (frame 30)
    frames = [walking[k] for k in (28, 29, 30, 31, 90, 91)]  # still, starting, then in view (t = 3 s)
    for frame in frames:
        alone = SyntheticSource("crossing_walkers", seed=3)[frame.index]
        np.testing.assert_array_equal(alone.color, frame.color)
        np.testing.assert_array_equal(alone.depth, frame.depth)
    assert not np.array_equal(frames[0].color, frames[-1].color)  # the walker came into view


@pytest.mark.parametrize("name", SEQUENCES)
def test_builtin_sequences_last_5_to_20_s_and_keep_their_truth(name: str) -> None:
    sequence = builtin_sequence(name)
    assert 5.0 <= sequence.duration <= 20.0
    assert len(SyntheticSource(name)) == round(sequence.duration * 30) + 1
    times = np.arange(0.0, sequence.duration + 1.0, 0.1)
    closest = 0.3 if name == "close_crossing" else 0.45  # its walkers pass 0.34 m apart, one behind the other
    for t in times:  # nobody's body overlaps anybody else's
        moment = sequence.at(float(t))
        xy = np.array([(p.x, p.y) for p in moment.people])
        gaps = np.linalg.norm(xy[:, None] - xy[None], axis=-1) + np.eye(len(xy)) * 9
        assert gaps.min() >= closest, (name, t)
    walking = {p.id for p in sequence.people if p.trajectory.path}
    groups = {sequence.at(float(t)).groups for t in times}
    if name == "crossing_walkers":
        assert groups == {((1, 2), (3, 4, 5))} and walking == {6, 7, 8}
    elif name == "drive_past_group":
        assert groups == {((1, 2, 3),)} and sequence.robot.end_time == pytest.approx(14.0)
    elif name == "file_behind_group":
        assert groups == {((1, 2, 3),)} and walking == {4, 5}
    elif name == "close_crossing":
        assert groups == {()} and walking == {1, 2}
    else:
        assert groups == {()} and walking == {1, 2, 3, 4}


def test_walkers_hide_the_conversations_for_a_while() -> None:
    source = _exact("crossing_walkers", shaded_color=False)
    hidden = {}
    for index in range(0, len(source), 15):
        truth = source[index].truth
        for person in truth.people[:5]:  # the five in conversation stand in view all along
            if not person.in_view:
                hidden.setdefault(person.id, []).append(index / 30)
    assert hidden, "no walker ever hides a member of a conversation"
    assert all(len(times) < 10 for times in hidden.values())  # hidden for a while, not for good


def test_a_frame_with_walkers_equals_the_same_moment_rendered_whole() -> None:
    source = _exact("crossing_walkers")  # standing people cast once, walkers drawn over them
    source[89]
    frame = source[90]  # t = 3 s: walker 6 in front of conversation A
    moment = builtin_sequence("crossing_walkers").at(3.0)
    assert moment.states[6].moving
    still = Scene("still", moment.seen_people, wall_distance=None)  # the same people as one static scene
    whole = SyntheticCamera(noise=DepthNoise.exact(), keypoint_noise=KeypointNoise(0.0, 0.0)).capture(still, 90)
    np.testing.assert_array_equal(frame.color, whole.color)
    np.testing.assert_array_equal(frame.depth, whole.depth)
    for moving, static in zip(frame.truth.people, whole.truth.people, strict=True):
        np.testing.assert_array_equal(moving.visible, static.visible)
