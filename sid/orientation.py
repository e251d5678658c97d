"""Which way a person faces, from their 3D keypoints: PCA body plane + shoulder/hip order (the paper's step 4).

A standing person's keypoints lie close to one upright plane: head to ankles span its vertical axis, shoulders and
hips its left-right axis; the body's front-back extent (nose, feet) is small. The eigenvector of the keypoints'
covariance with the smallest eigenvalue is therefore the body's normal, i.e. the facing axis up to sign. Projected
on the ground it gives a yaw; the sign comes from the left/right order: a person facing f has their left shoulder
on their left, so ``cross(f, left - right) > 0`` in the world's x-y plane (z up, counter-clockwise positive).

World frame: REP-103 (x forward, y left, z up, metres); yaw counter-clockwise from +x, radians in (-pi, pi].
"""

from __future__ import annotations

import math

import numpy as np

from sid.keypoints import LEFT_HIP, LEFT_SHOULDER, NUM_KEYPOINTS, RIGHT_HIP, RIGHT_SHOULDER

# Keypoints whose left/right order resolves the sign of the body normal: (left, right) shoulders and hips.
_LEFT = np.array([LEFT_SHOULDER, LEFT_HIP])
_RIGHT = np.array([RIGHT_SHOULDER, RIGHT_HIP])
# The keypoints are collinear (no plane) when the second principal spread is below 3 % of the first
# (eigenvalue ratio 1e-3): e.g. under 1.5 cm across for a 1.7 m person, less than depth noise.
_COLLINEAR_RATIO = 1e-3
# Left-right extent (m, across the facing direction, shoulders + hips summed) at which the front/back sign is
# trusted fully: an adult seen from the front shows ~0.55 m (0.37 m shoulders + 0.19 m hips). In side view the far
# shoulder and hip read the depth of the near torso surface and the extent collapses to a few centimetres, where
# keypoint noise flips the sign; quality falls in proportion (measured in tests/test_orientation.py).
_FULL_LEFT_RIGHT = 0.3
# An upright body plane has a near-horizontal normal; a normal more than 60 degrees from the ground plane
# (horizontal part < 0.5) means the points do not describe an upright body (a lying person, a few head points).
_MIN_HORIZONTAL_NORMAL = 0.5


def estimate_orientation(keypoints_world: np.ndarray) -> tuple[float | None, float]:
    """Facing yaw (rad, world frame) and its quality in [0, 1] from (17, 3) world keypoints (NaN rows = missing).

    Returns ``(None, 0.0)`` -- never a made-up angle -- when fewer than 3 keypoints are usable, when they are
    collinear or their best-fit plane is not upright, or when no left/right pair (shoulders or hips, both
    present) exists to tell front from back.

    quality = (1 - l3 / l2) * |n_xy| * min(1, w / 0.3 m): planarity (covariance eigenvalues l1 >= l2 >= l3; 1 for a
    clean plane, 0 when the normal is undetermined), times how horizontal the normal n is, times how far apart left
    and right keypoints lie across the facing direction (w, shoulders + hips; ~0.55 m from the front, a few cm in
    side view, where the front/back sign becomes a guess -- the paper's trouble near +-90 degrees).
    """
    points = np.asarray(keypoints_world, dtype=float)
    if points.shape != (NUM_KEYPOINTS, 3):
        raise ValueError(f"orientation: keypoints must be a ({NUM_KEYPOINTS}, 3) array, got shape {points.shape}")
    usable = np.isfinite(points).all(axis=1)
    present = points[usable]
    if len(present) < 3:
        return None, 0.0
    centred = present - present.sum(axis=0) / len(present)
    eigenvalues, eigenvectors = np.linalg.eigh(centred.T @ centred)  # ascending
    l3, l2, l1 = eigenvalues.tolist()
    if l2 <= _COLLINEAR_RATIO * l1:
        return None, 0.0
    nx, ny, _ = eigenvectors[:, 0].tolist()
    horizontal = math.hypot(nx, ny)
    if horizontal < _MIN_HORIZONTAL_NORMAL:
        return None, 0.0
    fx, fy = nx / horizontal, ny / horizontal

    # Left-right vector summed over the shoulder and hip pairs with both keypoints present.
    both = usable[_LEFT] & usable[_RIGHT]
    if not both.any():
        return None, 0.0
    lx, ly = (points[_LEFT[both], :2] - points[_RIGHT[both], :2]).sum(axis=0).tolist()
    across = fx * ly - fy * lx  # left-right extent across the facing axis (m)
    if across == 0.0:
        return None, 0.0
    if across < 0:
        fx, fy = -fx, -fy
    planarity = 1.0 - max(l3, 0.0) / l2
    quality = planarity * horizontal * min(1.0, abs(across) / _FULL_LEFT_RIGHT)
    return math.atan2(fy, fx), min(max(quality, 0.0), 1.0)
