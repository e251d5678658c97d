"""COCO-17 keypoint layout shared by every pose model, and the per-person 2D detection record."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sid.errors import InputError

__all__ = ["COCO_KEYPOINTS", "KP", "NUM_KEYPOINTS", "PoseDetection", "SKELETON"]

COCO_KEYPOINTS: tuple[str, ...] = (
    "nose", "left_eye", "right_eye", "left_ear", "right_ear",
    "left_shoulder", "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist",
    "left_hip", "right_hip", "left_knee", "right_knee", "left_ankle", "right_ankle",
)  # fmt: skip
NUM_KEYPOINTS = len(COCO_KEYPOINTS)
KP = {name: index for index, name in enumerate(COCO_KEYPOINTS)}
LEFT_SHOULDER, RIGHT_SHOULDER = KP["left_shoulder"], KP["right_shoulder"]

# Bones drawn in overlays (pairs of keypoint indices).
SKELETON: tuple[tuple[int, int], ...] = (
    (0, 1), (0, 2), (1, 3), (2, 4), (5, 6), (5, 7), (7, 9), (6, 8), (8, 10),
    (5, 11), (6, 12), (11, 12), (11, 13), (13, 15), (12, 14), (14, 16),
)  # fmt: skip


@dataclass
class PoseDetection:
    """One person found by a pose model, in colour-image pixels.

    keypoints: (17, 2) float (u, v) in COCO order; scores: (17,) in [0, 1] (model-specific scale);
    box: (4,) as (u_min, v_min, u_max, v_max); box_score: detection confidence.
    """

    keypoints: np.ndarray
    scores: np.ndarray
    box: np.ndarray
    box_score: float

    def __post_init__(self) -> None:
        self.keypoints = _exact("keypoints", self.keypoints, (NUM_KEYPOINTS, 2))
        self.scores = _exact("scores", self.scores, (NUM_KEYPOINTS,))
        self.box = _exact("box", self.box, (4,))
        self.box_score = float(self.box_score)


def _exact(field: str, value: object, shape: tuple[int, ...]) -> np.ndarray:
    """``value`` as a float array of exactly ``shape``: a ValueError naming ``field`` and the shape otherwise (a
    reshape would accept a (2, 17) array for (17, 2) and scramble it)."""
    array = np.asarray(value, dtype=float)
    if array.shape != shape:
        raise InputError(f"pose detection: {field} must have shape {shape}, got {array.shape}")
    return array
