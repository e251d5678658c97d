"""Synthetic COCO-17 skeletons of standing people in the world frame, for tests, demos and synthetic scenes.

World frame: REP-103 (x forward, y left, z up, metres; see ``sid.perception.people``). A person at (x, y) with yaw theta
faces (cos theta, sin theta); "left" below is the person's own left, (-sin theta, cos theta).
"""

from __future__ import annotations

import numpy as np

from sid.errors import InputError
from sid.perception.keypoints import COCO_KEYPOINTS

__all__ = ["skeleton_world"]

# Joint centres of an upright person with arms hanging, as fractions of body height: (forward, left, up) in the
# person's own frame, origin on the ground between the feet. Heights follow the anthropometric segment proportions
# of Drillis & Contini as tabulated by Winter ("Biomechanics and Motor Control of Human Movement"): shoulder 0.818 h,
# hip 0.530 h, knee 0.285 h, ankle 0.039 h, eyes 0.936 h. Joint centres sit inside the outer body widths of that
# table (shoulders 0.259 h, hips 0.191 h): we take 0.22 h between shoulder joints and 0.11 h between hip joints.
# The face (nose, eyes) sits in front of the ears.
_JOINT_FRACTIONS = {
    "nose": (0.055, 0.0, 0.915),
    "left_eye": (0.045, 0.018, 0.936),
    "right_eye": (0.045, -0.018, 0.936),
    "left_ear": (0.0, 0.045, 0.930),
    "right_ear": (0.0, -0.045, 0.930),
    "left_shoulder": (0.0, 0.110, 0.818),
    "right_shoulder": (0.0, -0.110, 0.818),
    "left_elbow": (0.0, 0.125, 0.630),
    "right_elbow": (0.0, -0.125, 0.630),
    "left_wrist": (0.020, 0.120, 0.485),
    "right_wrist": (0.020, -0.120, 0.485),
    "left_hip": (0.0, 0.055, 0.530),
    "right_hip": (0.0, -0.055, 0.530),
    "left_knee": (0.010, 0.055, 0.285),
    "right_knee": (0.010, -0.055, 0.285),
    "left_ankle": (0.0, 0.055, 0.039),
    "right_ankle": (0.0, -0.055, 0.039),
}
_BODY_FRACTIONS = np.array([_JOINT_FRACTIONS[name] for name in COCO_KEYPOINTS])
"""(17, 3) keypoints of a person of height 1 in their own (forward, left, up) frame, COCO order."""


def skeleton_world(x: float, y: float, theta: float, height: float = 1.7) -> np.ndarray:
    """(17, 3) world-frame COCO keypoints (metres) of an upright person standing at (x, y) facing yaw theta (rad)."""
    if not (np.isfinite(x) and np.isfinite(y) and np.isfinite(theta)):
        raise InputError(f"skeleton: position and yaw must be finite, got x={x}, y={y}, theta={theta}")
    if not (np.isfinite(height) and height > 0):
        raise InputError(f"skeleton: height must be positive (metres), got {height}")
    c, s = np.cos(theta), np.sin(theta)
    body = _BODY_FRACTIONS * height
    world = np.empty_like(body)
    world[:, 0] = x + c * body[:, 0] - s * body[:, 1]
    world[:, 1] = y + s * body[:, 0] + c * body[:, 1]
    world[:, 2] = body[:, 2]
    return world
