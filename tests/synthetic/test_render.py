"""Ray caster and body model of the synthetic scenes: exact geometry, labels, shading."""

from __future__ import annotations

import numpy as np
import pytest

from sid.perception.camera import Extrinsics, Intrinsics, project
from sid.perception.keypoints import KP
from sid.perception.mount import CameraMount
from sid.perception.skeleton import skeleton_world
from sid.synthetic.body import body_capsules, body_frame
from sid.synthetic.render import LABEL_GROUND, LABEL_NONE, LABEL_WALL, Background, Capsule, RayCaster

INTR = Intrinsics(160, 120, 100.0, 100.0, 79.5, 59.5)


def _caster(background: Background | None = None, mount: CameraMount | None = None) -> RayCaster:
    mount = mount or CameraMount()
    rotation = mount.rotation.T
    return RayCaster(INTR, Extrinsics(rotation, -rotation @ np.array([0.0, 0.0, mount.height])), background)


def _distance_to_axis(points: np.ndarray, shape: Capsule) -> np.ndarray:
    """Unit-space distance of camera-frame points to the shape's segment (1 on the surface)."""
    q = (points - shape.centre) @ np.linalg.inv(shape.axes).T
    nearest_z = np.clip(q[..., 2], -shape.half_length, shape.half_length)
    return np.sqrt(q[..., 0] ** 2 + q[..., 1] ** 2 + (q[..., 2] - nearest_z) ** 2)


@pytest.mark.parametrize("seed", range(6))
def test_ray_cast_hits_the_first_surface_point_and_misses_exactly(seed: int) -> None:
    rng = np.random.default_rng(seed)
    rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    semi = rng.uniform(0.05, 0.3, 3)
    shape = Capsule(np.array([rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), rng.uniform(1.5, 3.0)]),
                    rotation * semi, rng.uniform(0.0, 2.0))  # fmt: skip
    caster = RayCaster(INTR, Extrinsics(), Background(ground=False, wall_distance=None))
    # A camera frame equal to the world frame: pass the shape as a world-frame body.
    rendering = caster.render([[shape]])
    rays = np.stack(np.broadcast_arrays(caster._ray_x[None, :], caster._ray_y[:, None], 1.0), axis=-1)
    hit = rendering.label == 0
    assert hit.sum() > 50
    depth = rendering.depth[hit]
    # Depth is stored as float32 (~0.2 um at 3 m): allow 1e-3 of a semi-axis.
    np.testing.assert_allclose(_distance_to_axis(rays[hit] * depth[:, None], shape), 1.0, atol=1e-3)
    # No point of the ray before the hit (or anywhere along a missing ray) is inside the solid.
    samples = np.linspace(0.5, 1.0, 200)
    before = rays[hit][:, None, :] * (depth[:, None] * samples[None, :-1])[..., None]
    assert np.all(_distance_to_axis(before, shape) > 1.0 - 1e-3)
    along = rays[~hit][:, None, :] * np.linspace(0.5, 5.0, 400)[None, :, None]
    assert np.all(_distance_to_axis(along, shape) > 1.0)
    assert np.all(rendering.depth[~hit] == 0.0) and np.all(rendering.label[~hit] == LABEL_NONE)


def test_sphere_depth_and_shading_on_the_optical_axis() -> None:
    caster = RayCaster(INTR, Extrinsics(), Background(ground=False, wall_distance=None))
    sphere = Capsule.segment(np.array([0.0, 0.0, 2.0]), np.array([0.0, 0.0, 2.0]), 0.25)
    rendering = caster.render([[sphere]], shading=True)
    # The four pixels around the principal point (79.5, 59.5): first root of |t d - c|^2 = r^2.
    d = np.array([0.5 / INTR.fx, 0.5 / INTR.fy, 1.0])
    dc, dd = d @ np.array([0.0, 0.0, 2.0]), d @ d
    expected = (dc - np.sqrt(dc**2 - dd * (4.0 - 0.25**2))) / dd
    np.testing.assert_allclose(rendering.depth[59:61, 79:81], expected, rtol=1e-6)
    assert rendering.shade is not None
    normal = (expected * d - np.array([0.0, 0.0, 2.0])) / 0.25
    np.testing.assert_allclose(rendering.shade[59:61, 79:81], -normal @ d / np.sqrt(dd), rtol=1e-5)
    assert np.all((rendering.shade >= 0) & (rendering.shade <= 1))


def test_ground_and_wall_depth_follow_the_mount() -> None:
    mount = CameraMount(height=0.9)
    caster = _caster(Background(ground=True, wall_distance=4.0), mount)
    rendering = caster.render([])
    rows = np.arange(INTR.height)
    below = rows > INTR.cy
    ground_z = mount.height * INTR.fy / (rows[below] - INTR.cy)
    expected = np.where(ground_z < 4.0, ground_z, 4.0)
    np.testing.assert_allclose(rendering.depth[below, 40], expected, rtol=1e-5)
    assert np.all(rendering.label[~below, 40] == LABEL_WALL)
    assert np.all(rendering.label[below, 40][ground_z < 4.0] == LABEL_GROUND)
    open_space = _caster(Background(ground=True, wall_distance=None), mount).render([])
    assert np.all(open_space.depth[~below] == 0.0) and np.all(open_space.label[~below] == LABEL_NONE)


def test_person_torso_is_seen_at_its_distance_and_labelled() -> None:
    caster = _caster(Background())
    x = 2.5
    keypoints = skeleton_world(x, 0.0, np.pi)  # facing the camera
    rendering = caster.render([body_capsules(keypoints)])
    torso_centre = keypoints[[KP["left_shoulder"], KP["right_shoulder"], KP["left_hip"], KP["right_hip"]]].mean(0)
    u, v = np.rint(project(caster.world_to_camera.apply(torso_centre[None]), INTR)[0]).astype(int)
    assert rendering.label[v, u] == 0
    # The torso's front surface: 0.11 m (front-back semi-axis at 1.70 m) in front of the spine.
    assert rendering.depth[v, u] == pytest.approx(x - 0.11, abs=0.005)


def test_body_frame_and_shapes_follow_the_facing_direction() -> None:
    theta = 0.7
    keypoints = skeleton_world(1.0, 2.0, theta, height=1.8)
    frame = body_frame(keypoints)
    assert np.linalg.det(frame) == pytest.approx(1.0)  # a rotation, not a reflection
    forward, left, up = frame.T
    np.testing.assert_allclose(forward, [np.cos(theta), np.sin(theta), 0.0], atol=1e-9)
    np.testing.assert_allclose(up, [0.0, 0.0, 1.0], atol=1e-9)
    np.testing.assert_allclose(left, [-np.sin(theta), np.cos(theta), 0.0], atol=1e-9)
    shapes = body_capsules(keypoints, 1.8)
    assert len(shapes) == 15
    lowest = min(float((s.box_corners() @ np.array([0, 0, 1.0])).min()) for s in shapes)
    assert lowest == pytest.approx(0.0, abs=0.05)  # feet rest on the ground (boxes are a little loose)


def test_bad_input_is_rejected_with_a_reason() -> None:
    with pytest.raises(ValueError, match="17, 3"):
        body_capsules(np.zeros((5, 3)))
    with pytest.raises(ValueError, match="height"):
        body_capsules(skeleton_world(1.0, 0.0, 0.0), height=-1.0)
    with pytest.raises(ValueError, match="degenerate"):
        Capsule(np.zeros(3), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="finite"):
        Capsule(np.array([np.nan, 0, 0]), np.eye(3))
    with pytest.raises(ValueError, match="wall_distance"):
        Background(wall_distance=-1.0)


def test_shapes_behind_or_around_the_camera_do_not_break_the_render() -> None:
    caster = RayCaster(INTR, Extrinsics(), Background(ground=False, wall_distance=None))
    behind = Capsule.segment(np.array([0.0, 0.0, -2.0]), np.array([0.0, 0.5, -2.0]), 0.2)
    straddling = Capsule.segment(np.array([0.3, 0.0, -1.0]), np.array([0.3, 0.0, 3.0]), 0.1)
    rendering = caster.render([[behind], [straddling]])
    assert not np.any(rendering.label == 0)
    seen = rendering.label == 1
    assert seen.any() and np.all(rendering.depth[seen] > 0)


def test_bodies_drawn_over_a_base_rendering_match_one_render_of_all() -> None:
    caster = _caster()
    people = [(2.0, 0.3, 3.0), (3.0, -0.1, 0.5), (2.6, 0.0, -2.0)]  # the third stands between the other two
    bodies = []
    for x, y, theta in people:
        keypoints = skeleton_world(x, y, theta, 1.7)
        bodies.append(body_capsules(keypoints, 1.7))
    for shading in (False, True):
        whole = caster.render(bodies, shading=shading)
        base = caster.render(bodies[:2], shading=shading)
        layered = caster.render(bodies[2:], shading=shading, labels=[2], base=base)
        np.testing.assert_array_equal(layered.depth, whole.depth)
        np.testing.assert_array_equal(layered.label, whole.label)
        if shading:
            assert layered.shade is not None and whole.shade is not None
            np.testing.assert_array_equal(layered.shade, whole.shade)
    assert {0, 1, 2} <= set(np.unique(whole.label).tolist())
    with pytest.raises(ValueError, match="2 labels for 1 bodies"):
        caster.render(bodies[2:], labels=[2, 3])
    with pytest.raises(ValueError, match="base made with shading=True"):
        caster.render(bodies[2:], shading=True, labels=[2], base=caster.render(bodies[:2]))
