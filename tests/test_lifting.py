"""Lifting 2D keypoints to world-frame people on synthetic RGB-D frames with known skeletons."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sid.camera import Calibration, Extrinsics, Intrinsics, project
from sid.frames import CameraMount
from sid.keypoints import KP, NUM_KEYPOINTS, PoseDetection
from sid.lifting import LiftParams, lift_people
from sid.orientation import estimate_orientation
from sid.skeleton import skeleton_world

COLOR = Intrinsics(640, 480, 600.0, 600.0, 319.5, 239.5)
REGISTERED = Calibration(COLOR)
MOUNT = CameraMount(height=0.9, tilt=0.0)


def splat(depth: np.ndarray, pixels: np.ndarray, z: np.ndarray, half: int = 3) -> None:
    """Write z into a (2 half + 1)^2 square around each pixel, nearest wins (a crude depth render of joints)."""
    h, w = depth.shape
    for (u, v), value in zip(np.round(pixels).astype(int), z, strict=True):
        window = depth[max(v - half, 0) : min(v + half + 1, h), max(u - half, 0) : min(u + half + 1, w)]
        np.copyto(window, value, where=(window == 0) | (window > value))


def scene(
    people: list[tuple[float, float, float]], mount: CameraMount = MOUNT, calib: Calibration = REGISTERED
) -> tuple[list[PoseDetection], np.ndarray, list[np.ndarray]]:
    """Detections, a depth image (in the depth camera's grid when calib.depth is set) and the true keypoints.

    Keypoints outside the colour image get score 0 and a NaN truth row.
    """
    grid = calib.depth or calib.color
    depth = np.zeros((grid.height, grid.width), dtype=np.float32)
    detections, truths = [], []
    for x, y, theta in people:
        joints = skeleton_world(x, y, theta)
        camera = mount.world_to_camera(joints)
        pixels = project(camera, calib.color)
        if calib.depth is None:
            splat(depth, pixels, camera[:, 2])
        else:  # the depth camera sees p_d = R^T (p_c - t)
            extr = calib.depth_to_color
            in_depth = (camera - extr.translation) @ extr.rotation
            splat(depth, project(in_depth, calib.depth), in_depth[:, 2])
        box = np.r_[pixels.min(axis=0), pixels.max(axis=0)]
        inside = (pixels >= 0).all(axis=1) & (pixels[:, 0] < COLOR.width - 0.5) & (pixels[:, 1] < COLOR.height - 0.5)
        detections.append(PoseDetection(pixels, np.where(inside, 0.9, 0.0), box, 0.9))  # out of view: not seen
        truths.append(np.where(inside[:, None], joints, np.nan))
    return detections, depth, truths


def test_lifted_keypoints_position_and_facing_match_the_skeleton():
    layout = [(2.0, 0.4, math.radians(200)), (2.6, -0.5, math.radians(150))]
    detections, depth, truths = scene(layout)
    people = lift_people(detections, depth, REGISTERED, MOUNT)
    assert [p.id for p in people] == [0, 1]
    for person, truth, (_, _, theta) in zip(people, truths, layout, strict=True):
        np.testing.assert_allclose(person.keypoints_world, truth, atol=0.005)
        assert (person.x, person.y) == pytest.approx(tuple(np.nanmean(truth[:, :2], axis=0)), abs=0.005)
        assert abs((person.theta - theta + math.pi) % (2 * math.pi) - math.pi) < math.radians(3)
        assert person.orientation_quality > 0.5


def test_holes_low_scores_and_outlying_depths_drop_keypoints_never_placing_them_at_the_camera():
    detections, depth, truths = scene([(2.0, 0.0, math.pi)])
    detection = detections[0]
    pixels = np.round(detection.keypoints).astype(int)

    def paint(name: str, value: float) -> None:
        u, v = pixels[KP[name]]
        depth[v - 3 : v + 4, u - 3 : u + 4] = value

    paint("left_wrist", 0.0)  # hole: no depth at all
    paint("right_wrist", 7.5)  # beyond max_range
    paint("left_knee", 3.0)  # 1 m behind the body: fails the depth gate
    detection.scores[KP["nose"]] = 0.1  # not confident
    [person] = lift_people(detections, depth, REGISTERED, MOUNT)
    dropped = [KP[n] for n in ("left_wrist", "right_wrist", "left_knee", "nose")]
    assert np.isnan(person.keypoints_world[dropped]).all()
    kept = np.setdiff1d(np.arange(NUM_KEYPOINTS), dropped)
    np.testing.assert_allclose(person.keypoints_world[kept], truths[0][kept], atol=0.005)
    assert (person.x, person.y) == pytest.approx(tuple(np.nanmean(truths[0][kept, :2], axis=0)), abs=0.005)
    assert np.nanmin(np.linalg.norm(person.keypoints_world[:, :2], axis=1)) > 1.5


def test_a_detection_with_too_few_lifted_keypoints_gives_no_person():
    detections, depth, _ = scene([(2.0, 0.0, math.pi), (3.0, 1.0, math.pi)])
    detections[1].scores[:] = 0.05
    detections[1].scores[[KP["left_shoulder"], KP["right_shoulder"]]] = 0.9
    people = lift_people(detections, depth, REGISTERED, MOUNT, ids=[7, 8])
    assert [p.id for p in people] == [7]
    assert lift_people([], depth, REGISTERED, MOUNT) == []
    everything_missing = lift_people(detections[:1], np.zeros_like(depth), REGISTERED, MOUNT)
    assert everything_missing == []


def test_a_person_with_only_a_few_keypoints_is_placed_without_a_facing():
    detections, depth, truths = scene([(2.5, 0.0, math.pi)])
    detections[0].scores[:] = 0.05
    detections[0].scores[[KP["nose"], KP["left_eye"], KP["left_shoulder"]]] = 0.9  # no left/right pair
    [person] = lift_people(detections, depth, REGISTERED, MOUNT)
    assert person.theta is None and person.orientation_quality == 0.0
    assert person.x == pytest.approx(truths[0][[0, 1, 5], 0].mean(), abs=0.005)


def test_tilted_mount_and_unregistered_depth():
    mount = CameraMount(height=1.1, tilt=0.15)
    depth_intr = Intrinsics(640, 480, 580.0, 580.0, 318.0, 241.0)
    turn = math.radians(1.0)
    rotation = np.array([[math.cos(turn), 0, math.sin(turn)], [0, 1, 0], [-math.sin(turn), 0, math.cos(turn)]])
    calib = Calibration(COLOR, depth_intr, Extrinsics(rotation, np.array([0.015, 0.0, 0.0])))
    layout = [(2.2, 0.3, math.radians(190))]
    detections, depth, truths = scene(layout, mount, calib)
    [person] = lift_people(detections, depth, calib, mount)
    usable = ~np.isnan(person.keypoints_world[:, 0])
    assert usable.sum() >= 13
    np.testing.assert_allclose(person.keypoints_world[usable], truths[0][usable], atol=0.02)
    assert np.isnan(truths[0][~usable]).all(), "only keypoints out of view are missing"
    assert estimate_orientation(person.keypoints_world)[0] == pytest.approx(person.theta)


def test_bad_input_is_rejected():
    detections, depth, _ = scene([(2.0, 0.0, math.pi)])
    with pytest.raises(ValueError, match="1 ids for 0 detections"):
        lift_people([], depth, REGISTERED, MOUNT, ids=[1])
    with pytest.raises(ValueError, match="depth image is"):
        lift_people(detections, depth[:-1], REGISTERED, MOUNT)
    for field, value in [
        ("min_score", 1.5),
        ("min_keypoints", 0),
        ("patch", 4),
        ("max_range", 0.0),
        ("depth_gate", -1),
    ]:
        with pytest.raises(ValueError, match=field):
            LiftParams(**{field: value})


def test_bench_lifting_four_people(benchmark):
    """Lifting + PCA for four people (run with --benchmark-enable to time it)."""
    detections, depth, _ = scene([(2.5, -0.6, 2.5), (2.5, 0.6, -2.5), (3.2, -0.3, 3.0), (3.2, 0.5, 3.3)])
    people = benchmark(lift_people, detections, depth, REGISTERED, MOUNT)
    assert len(people) == 4 and all(p.theta is not None for p in people)
