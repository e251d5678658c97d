"""The synthetic RGB-D source: frames, ground truth, occlusion, determinism, the pose stand-in."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from sid.perception.align import depth_at_color_pixels
from sid.perception.camera import Calibration, deproject, project
from sid.perception.frame import Frame
from sid.perception.keypoints import KP
from sid.perception.robot_pose import RobotPose
from sid.sources import SourceError, open_source
from sid.sources.synthetic import SyntheticSource, scene_from_spec, synthetic_source
from sid.synthetic.layouts import layout
from sid.synthetic.noise import DepthNoise, KeypointNoise
from sid.synthetic.pose import TruthPose
from sid.synthetic.render import LABEL_NONE
from sid.synthetic.scene import Scene, ScenePerson
from sid.synthetic.sensor import D435I_COLOR, FrameTruth, SyntheticCamera
from sid.synthetic.sequence import SyntheticSequence
from tests.conftest import REPO_ROOT

TORSO = [KP["left_shoulder"], KP["right_shoulder"], KP["left_hip"], KP["right_hip"]]


def _torso_depth_pixel(camera: SyntheticCamera, scene: Scene, keypoints: np.ndarray) -> tuple[int, int, float]:
    """Depth-grid pixel of the torso centre and the depth of the torso's front surface there (person facing the
    camera, torso front 0.11 m before the spine)."""
    point = camera.world_to_depth(scene.mount).apply(keypoints[TORSO].mean(axis=0)[None])
    u, v = np.rint(project(point, camera.depth_intrinsics)[0]).astype(int)
    return u, v, float(point[0, 2]) - 0.11


def test_frame_fields_shapes_and_dtypes() -> None:
    frame = next(iter(SyntheticSource("S3", frames=1)))
    assert isinstance(frame, Frame) and frame.index == 0 and frame.timestamp == 0.0
    assert frame.color.shape == (720, 1280, 3) and frame.color.dtype == np.uint8
    assert frame.depth.shape == (480, 848) and frame.depth.dtype == np.float32
    calib = frame.calibration
    assert calib.depth is not None and calib.depth.width == 848 and calib.color.fx == 910.0
    np.testing.assert_allclose(calib.depth_to_color.translation, [0.015, 0.0, 0.0])
    assert np.all(frame.depth >= 0) and np.isfinite(frame.depth).all()
    truth = frame.truth
    assert isinstance(truth, FrameTruth) and truth.scene == "S3" and len(truth.people) == 3
    for person in truth.people:
        assert person.keypoints_world.shape == (17, 3) and person.keypoints_px.shape == (17, 2)
        assert person.visible.dtype == bool and person.observed.shape == (17,) and person.box.shape == (4,)
        assert not np.any(person.observed & ~person.visible)
    (group,) = truth.groups
    assert group.members == (0, 1, 2) and group.detectable
    assert group.interest_point == pytest.approx((2.2, 0.0), abs=1e-9) and group.area == pytest.approx(0.0)

    registered = SyntheticSource("S3", frames=1, registered=True)[0]
    assert registered.depth.shape == (720, 1280) and registered.calibration.depth is None


def test_torso_depth_is_the_true_distance_within_the_noise() -> None:
    scene = Scene("one", (ScenePerson(0, 2.5, 0.2, np.pi),))
    source = SyntheticSource(scene, frames=20, noise=DepthNoise(hole_fraction=0.0, edge_holes=0.0))
    keypoints = source[0].truth.people[0].keypoints_world
    u, v, expected = _torso_depth_pixel(source.camera, scene, keypoints)
    readings = np.array([frame.depth[v, u] for frame in source])
    sigma = source.camera.noise.rms(expected, 420.0)  # 10.9 mm at 2.39 m
    assert np.all(np.abs(readings - expected) < 4 * sigma + 0.001)
    assert readings.std() == pytest.approx(sigma, rel=0.5)  # 20 samples: a loose check that noise is there
    assert abs(readings.mean() - expected) < 3 * sigma / np.sqrt(len(readings)) + 0.0005


def test_person_behind_another_has_hidden_keypoints() -> None:
    scene = Scene("occluded", (ScenePerson(0, 2.0, 0.0, np.pi), ScenePerson(1, 3.5, 0.02, np.pi)), wall_distance=6.0)
    truth = SyntheticSource(scene, frames=1)[0].truth
    front, back = truth.people
    assert front.visible[TORSO].all() and front.visible[KP["nose"]]
    assert not back.visible[TORSO].any() and not back.observed[TORSO].any()
    # Same size, further away: the back person's image lies almost entirely inside the front person's.
    assert back.visible.sum() <= 2
    detections = TruthPose()(SyntheticSource(scene, frames=1)[0])
    assert len(detections) == 1  # the hidden person has fewer than 3 observed keypoints


def test_side_by_side_people_are_all_visible_and_keypoints_project_onto_their_bodies() -> None:
    source = SyntheticSource("S2", frames=1, keypoint_noise=KeypointNoise(0.0, 0.0))
    frame = source[0]
    exact = source.camera.exact_depth(source.scene)
    to_depth = source.camera.world_to_depth(source.scene.mount)
    for index, person in enumerate(frame.truth.people):
        assert person.visible.all() and person.observed.all()
        np.testing.assert_array_equal(person.observed_px, person.keypoints_px)
        # Torso and head keypoints lie inside the body: their depth pixel shows this person.
        px = np.rint(project(to_depth.apply(person.keypoints_world[TORSO]), source.camera.depth_intrinsics))
        assert np.all(exact.label[px[:, 1].astype(int), px[:, 0].astype(int)] == index)
        u0, v0, u1, v1 = person.box
        assert np.all((person.keypoints_px[:, 0] >= u0) & (person.keypoints_px[:, 0] <= u1))


def test_lifting_observed_keypoints_recovers_positions() -> None:
    """The perception path on synthetic data: observed pixels -> depth lookup -> 3D -> world mean."""
    frame = SyntheticSource("S3", frames=1, seed=5)[0]
    calib: Calibration = frame.calibration
    mount = frame.truth.mount
    for person in frame.truth.people:
        px = person.observed_px[person.observed]
        depth = depth_at_color_pixels(frame.depth, px, calib)
        ok = np.isfinite(depth)
        world = mount.camera_to_world(deproject(px[ok], depth[ok], calib.color))
        # The surface is a few cm nearer than the joints; positions agree within the paper's 0.2 m.
        assert np.hypot(world[:, 0].mean() - person.x, world[:, 1].mean() - person.y) < 0.2


def test_seed_and_index_determine_a_frame() -> None:
    first = SyntheticSource("S1", frames=3, seed=11)
    again = SyntheticSource("S1", frames=3, seed=11)
    other = SyntheticSource("S1", frames=3, seed=12)
    frames, frames_again = list(first), list(again)
    for a, b in zip(frames, frames_again, strict=True):
        np.testing.assert_array_equal(a.depth, b.depth)
        np.testing.assert_array_equal(a.color, b.color)
        np.testing.assert_array_equal(a.truth.people[0].observed_px, b.truth.people[0].observed_px)
    assert not np.array_equal(frames[0].depth, frames[1].depth)  # fresh noise every frame
    assert not np.array_equal(frames[0].depth, other[0].depth)
    np.testing.assert_array_equal(first[2].depth, frames[2].depth)  # random access = iteration
    assert frames[2].timestamp == pytest.approx(2 / 30)


def test_truth_pose_reports_observed_keypoints_with_scores() -> None:
    frame = SyntheticSource("S4", frames=1, keypoint_noise=KeypointNoise(sigma_px=1.0, drop=0.3))[0]
    pose = TruthPose(score_observed=0.8, score_self_occluded=0.4, score_hidden=0.1)
    detections = pose(frame)
    assert len(detections) == 4
    for detection, person in zip(detections, frame.truth.people, strict=True):
        # The outer members of S4 are turned 68 deg from the camera: their far shoulder and hip hide behind them.
        expected = np.where(person.observed, np.where(person.self_occluded, 0.4, 0.8), 0.1)
        np.testing.assert_array_equal(detection.scores, expected)
        np.testing.assert_array_equal(detection.keypoints, person.observed_px)
        assert 0 < detection.box_score <= 0.8
    assert pose.contract == "truth" and pose.input_size is None
    with pytest.raises(ValueError, match="ground truth"):
        pose(Frame(0, frame.color, frame.depth, frame.calibration))
    with pytest.raises(ValueError, match="score_hidden"):
        TruthPose(score_observed=0.1, score_hidden=0.5)


def test_self_occlusion_profile_and_back_views() -> None:
    profile = Scene("profile", (ScenePerson(0, 2.5, 0.0, np.pi / 2),))  # facing +y: its left side towards the camera
    back = Scene("back", (ScenePerson(0, 2.5, 0.0, 0.0),))  # facing away from the camera
    side = SyntheticSource(profile, frames=1, keypoint_noise=KeypointNoise(0.0, 0.0))[0].truth.people[0]
    far_side = [KP[f"right_{part}"] for part in ("shoulder", "hip", "knee")]
    near_side = [KP[f"left_{part}"] for part in ("shoulder", "hip", "knee")]
    assert side.self_occluded[far_side].all() and not side.self_occluded[near_side].any()
    assert side.visible.all() or not side.visible[KP["left_ankle"]]  # only the ankles may leave the image
    behind = SyntheticSource(back, frames=1)[0]
    person = behind.truth.people[0]
    face = [KP["nose"], KP["left_eye"], KP["right_eye"]]
    assert person.self_occluded[face].all() and not person.self_occluded[TORSO].any()
    scores = TruthPose()(behind)[0].scores
    assert np.all(scores[face] == 0.05) and np.all(scores[TORSO] == 0.9)
    side_scores = TruthPose()(SyntheticSource(profile, frames=1, keypoint_noise=KeypointNoise(0.0, 0.0))[0])[0].scores
    assert np.all(side_scores[far_side] == 0.5)


def test_specs_scenarios_and_errors(tmp_path: Path) -> None:
    assert scene_from_spec("synthetic:s5") == layout("S5")
    path = tmp_path / "two.json"
    path.write_text(json.dumps({"people": [{"x": 2.0, "y": 0.4, "theta": -1.5}, {"x": 2.0, "y": -0.4, "theta": 1.5}]}))
    source = synthetic_source(f"synthetic:{path}", frames=2, seed=1)
    assert len(source) == 2 and [p.id for p in source.scene.people] == [0, 1]
    assert (
        len(source.scene.people) == 2
        and not isinstance(source.scene, SyntheticSequence)
        and source[0].robot_pose is None
    )
    assert len(SyntheticSource("S1")) == 30  # a static scene: 30 frames unless asked
    with pytest.raises(SourceError, match="neither a built-in scene .*crossing_walkers"):
        synthetic_source("synthetic:S7")
    with pytest.raises(SourceError, match="empty spec"):
        synthetic_source("synthetic:")
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    with pytest.raises(SourceError, match="people"):
        synthetic_source(f"synthetic:{bad}")
    example = REPO_ROOT / "examples" / "conversation.json"
    if example.is_file():  # a costmap scenario file, through open_source as `sid detect` does
        frame = next(iter(open_source(f"synthetic:{example}", frames=1)))
        assert frame.truth.scene == "conversation" and len(frame.truth.people) == 4
        assert frame.robot_pose == RobotPose(0.0, 0.0, 0.0) and frame.truth.frame_id == "map"
    with pytest.raises(ValueError, match="frames"):
        SyntheticSource("S1", frames=-1)
    with pytest.raises(TypeError, match="Scene"):
        SyntheticSource(42)
    with pytest.raises(ValueError, match="occlusion_margin"):
        SyntheticSource("S1", occlusion_margin=-0.1)
    with pytest.raises(ValueError, match="fps"):
        SyntheticSource("S1", fps=0.0)
    with pytest.raises(IndexError):
        SyntheticSource("S1", frames=1)[1]


def test_plain_colour_option_and_exact_data() -> None:
    source = SyntheticSource("S1", frames=1, shaded_color=False, noise=DepthNoise.exact())
    frame = source[0]
    assert np.all(frame.color == 128)
    exact = source.camera.exact_depth(source.scene)
    np.testing.assert_array_equal(frame.depth, exact.depth)
    assert not np.any(exact.label == LABEL_NONE)  # a wall at 5 m closes the view


def test_registered_depth_is_cast_with_the_colour_image() -> None:
    """With registered depth the shaded colour render carries depth and labels: they equal a plain depth render."""
    calibration = Calibration(D435I_COLOR.scaled(640, 360))
    shaded, plain = (
        SyntheticSource("S4", frames=1, noise=DepthNoise.exact(), calibration=calibration, shaded_color=color)
        for color in (True, False)
    )
    np.testing.assert_array_equal(shaded[0].depth, plain[0].depth)
    np.testing.assert_array_equal(
        shaded.camera.exact_depth(shaded.scene).label, plain.camera.exact_depth(plain.scene).label
    )
