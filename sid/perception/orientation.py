"""Which way a person faces, from their 3D keypoints: PCA body plane + left/right order (the paper's step 4).

A standing person's keypoints lie close to one upright plane: head to ankles span its vertical axis, shoulders and
hips its left-right axis; the body's front-back extent (nose, feet) is small. The eigenvector of the keypoints'
covariance with the smallest eigenvalue is therefore the body's normal, i.e. the facing axis up to sign. Projected
on the ground it gives a yaw; the sign comes from the left/right order: a person facing f has their left side on
their left, so ``cross(f, left - right) > 0`` in the world's x-y plane (z up, counter-clockwise positive). The
paper uses the shoulders; we sum the left - right vectors of every pair present among shoulders, hips, ears, knees,
ankles and eyes (``SIGN_PAIRS``), so that a person with one shoulder and one hip hidden behind someone else still
gets a facing. Elbows and wrists are left out: folded or crossed arms put them on the wrong side.

World frame: REP-103 (x forward, y left, z up, metres); yaw counter-clockwise from +x, radians in (-pi, pi].

Typical adult left-right separations (m), used to judge the left-right evidence here and to complete a person's
hidden far side in ``sid.perception.lifting`` (keypoint separations measured on real people: docs/parameters.md):

- shoulders ``SHOULDER_SEPARATION`` = 0.34: between the biacromial breadth, 0.355 m (women) and 0.400 m (men) at the
  50th percentile of British adults (Pheasant & Haslegrave, "Bodyspace", 3rd ed.; US adults alike), and the
  narrower spacing of COCO shoulder keypoints, which pose models put inside the bony acromion. (The synthetic
  skeleton, ``sid.perception.skeleton``, uses 0.22 h = 0.374 m for a 1.70 m person.)
- hips ``HIP_SEPARATION`` = 0.18: hip-joint centres sit ~36 % of the inter-ASIS breadth (~0.23-0.26 m) either side
  of the midline (Bell, Pedersen & Brand, J. Biomech. 1990; Harrington et al., J. Biomech. 2007): 0.17-0.19 m.
- ears ``EAR_SEPARATION`` = 0.15: head breadth, 0.145 m (women) and 0.155 m (men) at the 50th percentile (Pheasant).
- eyes ``EYE_SEPARATION`` = 0.063: the adult interpupillary distance (Dodgson, Proc. SPIE 5291, 2004: mean 63 mm).
- knees and ankles: a standing person's legs hang below the hip joints, so the hip separation.
"""

from __future__ import annotations

import math

import numpy as np

from sid.errors import InputError
from sid.perception.keypoints import KP, NUM_KEYPOINTS

__all__ = [
    "EAR_SEPARATION",
    "EYE_SEPARATION",
    "HIP_SEPARATION",
    "SHOULDER_SEPARATION",
    "SIGN_PAIRS",
    "estimate_orientation",
    "estimate_orientations",
]

SHOULDER_SEPARATION = 0.34
HIP_SEPARATION = 0.18
EAR_SEPARATION = 0.15
EYE_SEPARATION = 0.063

SIGN_PAIRS: tuple[tuple[int, int, float], ...] = (
    (KP["left_shoulder"], KP["right_shoulder"], SHOULDER_SEPARATION),
    (KP["left_hip"], KP["right_hip"], HIP_SEPARATION),
    (KP["left_ear"], KP["right_ear"], EAR_SEPARATION),
    (KP["left_knee"], KP["right_knee"], HIP_SEPARATION),
    (KP["left_ankle"], KP["right_ankle"], HIP_SEPARATION),
    (KP["left_eye"], KP["right_eye"], EYE_SEPARATION),
)
"""(left keypoint, right keypoint, typical frontal separation in m) of the pairs whose order gives the facing sign."""

_LEFT = np.array([pair[0] for pair in SIGN_PAIRS])
_RIGHT = np.array([pair[1] for pair in SIGN_PAIRS])
# The keypoints are collinear (no plane) when the second principal spread is below 3 % of the first
# (eigenvalue ratio 1e-3): e.g. under 1.5 cm across for a 1.7 m person, less than depth noise.
_COLLINEAR_RATIO = 1e-3
# The front/back sign is trusted fully when the pairs present show at least this fraction of their typical frontal
# separation across the facing axis: cos 60 deg, what a correctly measured body turned 60 deg still shows in its
# image. The 3D separation does not depend on the view when every keypoint's depth is right; it collapses when the
# far side of a person in profile reads the near side's surface, where keypoint noise flips the sign (as
# tests/perception/test_orientation.py shows), and quality falls in proportion.
_FULL_FRACTION = 0.5
# A pair with a keypoint put in place by the far-side completion of ``sid.perception.lifting`` (``inferred``) counts a
# quarter: its separation comes from the anthropometric table and from which side the pose model scored lower, not from
# a measured depth, so a side view restored by completion alone rates half of a measured one.
_INFERRED_WEIGHT = 0.25
# An upright body plane has a near-horizontal normal; a normal more than 60 degrees from the ground plane
# (horizontal part < 0.5) means the points do not describe an upright body (a lying person, a few head points).
_MIN_HORIZONTAL_NORMAL = 0.5


def estimate_orientation(keypoints_world: np.ndarray, inferred: np.ndarray | None = None) -> tuple[float | None, float]:
    """Facing yaw (rad, world frame) and its quality in [0, 1] from (17, 3) world keypoints (NaN rows = missing).

    inferred: optional (17,) bool, keypoints whose depth was inferred rather than measured (``sid.perception.lifting``'s
    far-side completion); they take part fully in the plane fit and count less as left/right evidence.

    Returns ``(None, 0.0)`` -- never a made-up angle -- when fewer than 3 keypoints are usable, when they are
    collinear or their best-fit plane is not upright, or when no left/right pair of ``SIGN_PAIRS`` (both keypoints
    present) exists to tell front from back, or the pairs present cancel exactly.

    quality = (1 - l3 / l2) * |n_xy| * min(1, a / (0.5 * W)): planarity (covariance eigenvalues l1 >= l2 >= l3; 1 for
    a clean plane, 0 when the normal is undetermined), times how horizontal the normal n is, times the left/right
    evidence: a, the pairs' summed left-right extent across the facing direction (inferred pairs weighted 1/4),
    against W, the sum of their typical frontal separations. A correctly measured body shows a = W from any side;
    in profile the far side reads the near side's depth, a collapses to a few centimetres and the front/back sign
    becomes a guess (the paper's trouble near +-90 degrees).
    """
    points = np.asarray(keypoints_world, dtype=float)
    if points.shape != (NUM_KEYPOINTS, 3):
        raise InputError(f"orientation: keypoints must be a ({NUM_KEYPOINTS}, 3) array, got shape {points.shape}")
    if inferred is not None:
        inferred = np.asarray(inferred, dtype=bool)
        if inferred.shape != (NUM_KEYPOINTS,):
            raise InputError(f"orientation: inferred must be a ({NUM_KEYPOINTS},) mask, got shape {inferred.shape}")
    return _orientations(points[None], None if inferred is None else inferred[None])[0]


def estimate_orientations(
    keypoints_world: np.ndarray, inferred: np.ndarray | None = None
) -> list[tuple[float | None, float]]:
    """``estimate_orientation`` for P people at once: (P, 17, 3) world keypoints, optional (P, 17) inferred mask.

    Returns one (yaw, quality) per person, as ``estimate_orientation`` of each alone would, for little more than the
    cost of one (``sid.perception.lifting`` calls it once per frame).
    """
    points = np.asarray(keypoints_world, dtype=float)
    if points.ndim != 3 or points.shape[1:] != (NUM_KEYPOINTS, 3):
        raise InputError(f"orientation: keypoints must be a (P, {NUM_KEYPOINTS}, 3) array, got shape {points.shape}")
    if inferred is not None:
        inferred = np.asarray(inferred, dtype=bool)
        if inferred.shape != points.shape[:2]:
            raise InputError(f"orientation: inferred must be a {points.shape[:2]} mask, got shape {inferred.shape}")
    return _orientations(points, inferred)


def _orientations(points: np.ndarray, inferred: np.ndarray | None) -> list[tuple[float | None, float]]:
    """``estimate_orientations`` of checked (P, 17, 3) float points and (P, 17) bool ``inferred`` (or None)."""
    usable = np.isfinite(points).all(axis=2)
    counts = usable.sum(axis=1)
    both = usable[:, _LEFT] & usable[:, _RIGHT]
    # Everyone's scatter matrix at once, with a missing keypoint's row zero: it adds nothing to the sums (x + 0.0 is
    # x), so each person's matrix is the one of their usable keypoints alone.
    rows = usable[..., None]
    masked = np.where(rows, points, 0.0)
    # (People without keypoints divide their zero sums by 1, not 0: their rows are zeroed anyway.)
    centred = np.where(rows, masked - masked.sum(axis=1, keepdims=True) / np.maximum(counts, 1)[:, None, None], 0.0)
    eigenvalues, eigenvectors = np.linalg.eigh(centred.transpose(0, 2, 1) @ centred)  # ascending, per person
    flags = inferred.tolist() if inferred is not None else [None] * len(points)
    return [
        # Without 3 keypoints or a left/right pair: no facing, whatever the plane.
        _facing(values, normal, xy, pairs, person_flags) if count >= 3 and any(pairs) else (None, 0.0)
        for count, pairs, values, normal, xy, person_flags in zip(
            counts.tolist(),
            both.tolist(),
            eigenvalues.tolist(),
            eigenvectors[:, :, 0].tolist(),
            points[:, :, :2].tolist(),
            flags,
            strict=True,
        )
    ]


def _facing(
    eigenvalues: list[float],
    normal: list[float],
    xy: list[list[float]],
    both: list[bool],
    flags: list[bool] | None,
) -> tuple[float | None, float]:
    """(yaw, quality) of one person (``estimate_orientation``) from the keypoints' covariance eigenvalues (ascending)
    and smallest-eigenvalue eigenvector ``normal``, their world (x, y) ``xy`` (17 rows), which ``SIGN_PAIRS`` have
    both keypoints (``both``) and the inferred flags (plain floats: six pairs are cheaper in Python than in numpy)."""
    l3, l2, l1 = eigenvalues
    if l2 <= _COLLINEAR_RATIO * l1:
        return None, 0.0
    nx, ny, _ = normal
    horizontal = math.hypot(nx, ny)
    if horizontal < _MIN_HORIZONTAL_NORMAL:
        return None, 0.0
    fx, fy = nx / horizontal, ny / horizontal

    # Left-right extent across the facing axis, summed over the pairs with both keypoints present.
    lx = ly = typical = 0.0
    for (left, right, separation), present in zip(SIGN_PAIRS, both, strict=True):
        if present:
            weight = _INFERRED_WEIGHT if flags is not None and (flags[left] or flags[right]) else 1.0
            lx += weight * (xy[left][0] - xy[right][0])
            ly += weight * (xy[left][1] - xy[right][1])
            typical += separation
    across = fx * ly - fy * lx  # (m)
    if across == 0.0:
        return None, 0.0
    if across < 0:
        fx, fy = -fx, -fy
    planarity = 1.0 - max(l3, 0.0) / l2
    evidence = min(1.0, abs(across) / (_FULL_FRACTION * typical))
    quality = planarity * horizontal * evidence
    yaw = math.atan2(fy, fx)  # -pi for (-1, -0.0): the same direction as pi, which the range (-pi, pi] keeps
    return math.pi if yaw == -math.pi else yaw, min(max(quality, 0.0), 1.0)
