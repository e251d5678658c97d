"""The person record: where someone stands and which way they face, on the ground plane.

Frames follow REP-103/105: ``base_footprint`` (the robot's ground frame, x forward, y left, z up) or ``map``; the
record does not say which (``sid.perception.pipeline.FrameResult.frame_id`` does). theta is the yaw of the facing
direction, counter-clockwise from +x, in radians; a person at (x, y) faces (cos theta, sin theta).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Person"]


@dataclass
class Person:
    """One person on the ground plane (base_footprint or map, metres, radians).

    theta is None when the orientation is unknown (too few keypoints, degenerate geometry).
    orientation_quality in [0, 1]: how far theta can be trusted, the product of how planar the keypoints are, how
    horizontal that plane's normal is and how much left/right evidence tells front from back
    (``sid.perception.orientation.estimate_orientation``); 0 = unknown. A facing given without one is trusted (1), as
    every reader of facings does (scenario files, ``sid groups`` lines, the benchmarks' annotations).
    keypoints_world: optional (17, 3) keypoints in the same frame (z up from the ground), NaN rows where a keypoint
    was unusable.
    """

    id: int
    x: float
    y: float
    theta: float | None = None
    orientation_quality: float = 1.0
    keypoints_world: np.ndarray | None = field(default=None, repr=False)

    @property
    def position(self) -> np.ndarray:
        return np.array([self.x, self.y])

    @property
    def facing(self) -> np.ndarray | None:
        """Unit facing vector (same frame), or None when unknown."""
        return None if self.theta is None else np.array([np.cos(self.theta), np.sin(self.theta)])
