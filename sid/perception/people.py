"""The person record: where someone stands and which way they face, in the world frame.

World frame (REP-103, the paper's top view of the ground): x forward along the camera's depth axis, y to the
left, z up; origin on the ground below the camera. theta is the yaw of the facing direction, counter-clockwise
from +x, in radians; a person at (x, y) faces (cos theta, sin theta).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Person:
    """One person in the world frame.

    theta is None when the orientation is unknown (too few keypoints, degenerate geometry).
    orientation_quality in [0, 1]: how planar the keypoints are (1 = clean plane, 0 = unknown).
    keypoints_world: optional (17, 3) world-frame keypoints, NaN rows where a keypoint was unusable.
    """

    id: int
    x: float
    y: float
    theta: float | None = None
    orientation_quality: float = 0.0
    keypoints_world: np.ndarray | None = field(default=None, repr=False)

    @property
    def position(self) -> np.ndarray:
        return np.array([self.x, self.y])

    @property
    def facing(self) -> np.ndarray | None:
        """Unit facing vector in the world frame, or None when unknown."""
        return None if self.theta is None else np.array([np.cos(self.theta), np.sin(self.theta)])
