"""A person's body as simple solids built around their 3D keypoints (world frame, metres).

Fifteen capsules: an elliptic torso, an ellipsoid head, a neck, upper arms, forearms, hands, thighs, shins and feet.
Joints (COCO keypoints) lie on the axes of the limbs and inside the torso and head, so a depth camera sees the
body's surface a few centimetres in front of each keypoint, as it does on a real person. Sizes are typical adult
proportions for a 1.70 m person (torso 0.34 x 0.22 m, thigh radius 7.5 cm) scaled by ``height / 1.70``.
"""

from __future__ import annotations

import numpy as np

from sid.checks import check_number
from sid.errors import InputError
from sid.perception.keypoints import KP, NUM_KEYPOINTS
from sid.synthetic.render import Capsule

__all__ = ["REFERENCE_HEIGHT", "body_capsules", "body_frame"]

REFERENCE_HEIGHT = 1.70  # m: the body sizes below are for this height

# (from keypoint, to keypoint, radius in m at the reference height)
_LIMBS: tuple[tuple[str, str, float], ...] = (
    ("left_shoulder", "left_elbow", 0.050),
    ("left_elbow", "left_wrist", 0.040),
    ("right_shoulder", "right_elbow", 0.050),
    ("right_elbow", "right_wrist", 0.040),
    ("left_hip", "left_knee", 0.075),
    ("left_knee", "left_ankle", 0.055),
    ("right_hip", "right_knee", 0.075),
    ("right_knee", "right_ankle", 0.055),
)
_HAND_RADIUS = 0.045
_NECK_RADIUS = 0.055
_FOOT_RADIUS = 0.040
_FOOT_LENGTH = 0.15  # ankle to toe tip along the facing direction
_TORSO_SEMI = (0.11, 0.17, 0.08)  # front-back, lateral, rounded ends (m)
_TORSO_BELOW_HIPS = 0.06  # the torso reaches this far below the hip joints (pelvis)
_TORSO_ABOVE_SHOULDERS = 0.04
_HEAD_SEMI = (0.10, 0.085, 0.115)  # front-back, lateral (ears included), vertical (m)


def _scaled(semi_axes: tuple[float, float, float], s: float) -> tuple[float, float, float]:
    return (semi_axes[0] * s, semi_axes[1] * s, semi_axes[2] * s)


def body_frame(keypoints: np.ndarray) -> np.ndarray:
    """(3, 3) rotation (determinant +1) whose columns are the body's forward, left and up directions (world frame,
    as REP-103's x, y, z), from the shoulders and hips of (17, 3) world keypoints."""
    mid_hip = (keypoints[KP["left_hip"]] + keypoints[KP["right_hip"]]) / 2
    mid_shoulder = (keypoints[KP["left_shoulder"]] + keypoints[KP["right_shoulder"]]) / 2
    up = _unit(mid_shoulder - mid_hip, "hips and shoulders coincide")
    left = keypoints[KP["left_shoulder"]] - keypoints[KP["right_shoulder"]]
    left = _unit(left - (left @ up) * up, "shoulders lie on the body axis")
    return np.stack([np.cross(left, up), left, up], axis=1)


def body_capsules(keypoints: np.ndarray, height: float = REFERENCE_HEIGHT) -> list[Capsule]:
    """Solids of one person from their (17, 3) world-frame COCO keypoints; ``height`` (m) scales the radii."""
    keypoints = np.asarray(keypoints, dtype=float)
    if keypoints.shape != (NUM_KEYPOINTS, 3) or not np.all(np.isfinite(keypoints)):
        raise InputError(f"body: expected finite (17, 3) world keypoints, got shape {keypoints.shape}")
    check_number("body", "height", height, low=0, low_open=True, unit="metres")
    s = height / REFERENCE_HEIGHT
    frame = body_frame(keypoints)
    forward, left, up = frame.T
    kp = {name: keypoints[index] for name, index in KP.items()}
    mid_hip = (kp["left_hip"] + kp["right_hip"]) / 2
    mid_shoulder = (kp["left_shoulder"] + kp["right_shoulder"]) / 2
    head_centre = (kp["left_ear"] + kp["right_ear"]) / 2

    bottom = mid_hip - _TORSO_BELOW_HIPS * s * up
    top = mid_shoulder + _TORSO_ABOVE_SHOULDERS * s * up
    torso_semi = _scaled(_TORSO_SEMI, s)
    torso_length = max(float(np.linalg.norm(top - bottom)) - 2 * torso_semi[2], 0.0)
    shapes = [
        Capsule.oriented((top + bottom) / 2, frame, torso_semi, torso_length),
        Capsule.oriented(head_centre, frame, _scaled(_HEAD_SEMI, s)),
        Capsule.segment(mid_shoulder, head_centre, _NECK_RADIUS * s),
    ]
    shapes += [Capsule.segment(kp[a], kp[b], r * s) for a, b, r in _LIMBS]
    shapes += [Capsule.segment(kp[w], kp[w], _HAND_RADIUS * s) for w in ("left_wrist", "right_wrist")]
    for ankle in ("left_ankle", "right_ankle"):
        heel = kp[ankle].copy()
        heel[2] = _FOOT_RADIUS * s  # the foot rests on the ground
        shapes.append(Capsule.segment(heel, heel + (_FOOT_LENGTH - _FOOT_RADIUS) * s * forward, _FOOT_RADIUS * s))
    return shapes


def _unit(vector: np.ndarray, problem: str) -> np.ndarray:
    norm = float(np.linalg.norm(vector))
    if norm < 1e-6:
        raise InputError(f"body: cannot orient the body, {problem}")
    return vector / norm
