"""From 2D pose detections and depth to people in the world frame (the paper's steps 2-4).

Per detection: each confident keypoint takes the depth of its colour pixel (``sid.align.depth_at_color_pixels``,
robust to holes and silhouette edges), is deprojected with the colour intrinsics K_c (d * K_c^-1 [u v 1]) and moved
to the world frame with the camera mount. Keypoints without a valid depth are dropped, never placed at the camera.
Position = mean of the lifted keypoints' world x, y; facing = ``sid.orientation.estimate_orientation``.

Frames: camera optical (x right, y down, z forward) -> world (REP-103: x forward, y left, z up, origin on the
ground below the camera; see ``sid.frames``). Units: metres, radians.

Note: depth is read on the body's surface, a few centimetres in front of the joints, so positions sit that much
closer to the camera than the skeleton's centre; the paper does the same.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sid.align import depth_at_color_pixels
from sid.camera import Calibration, deproject
from sid.frames import CameraMount
from sid.keypoints import NUM_KEYPOINTS, PoseDetection
from sid.orientation import estimate_orientation
from sid.people import Person


@dataclass(frozen=True)
class LiftParams:
    """How keypoints become 3D points.

    min_score: a keypoint is used when its score is at least this. 0.3 is a common visibility cut for MoveNet and
      YOLO-pose keypoints, but scores are model-specific (our float ONNX conversions differ from the int8 TFLite
      originals by up to 0.35): set it per model.
    min_keypoints: a detection with fewer lifted keypoints gives no Person. 3: fewer cannot be placed reliably
      (one occluded limb at a wrong depth would decide the position) and cannot give a facing direction.
    patch: side (pixels, odd) of the depth window read around each keypoint. 5, as the paper's authors did.
    max_range: keypoints farther than this from the camera (m, optical z) are dropped. 6.0: D435-class depth
      noise grows with range squared (~2 % at 2 m, ~20 cm at 6 m), beyond which body orientation is noise.
    depth_gate: keypoints whose depth differs from the person's median keypoint depth by more than this (m) are
      dropped. 0.6: a standing body spans ~0.3 m in depth even in side view; a keypoint beyond that read the wall
      or a person behind (a keypoint on the silhouette edge, or a mislocalised wrist).
    """

    min_score: float = 0.3
    min_keypoints: int = 3
    patch: int = 5
    max_range: float = 6.0
    depth_gate: float = 0.6

    def __post_init__(self) -> None:
        if not (math.isfinite(self.min_score) and 0 <= self.min_score <= 1):
            raise ValueError(f"lift: min_score must be in [0, 1], got {self.min_score}")
        if int(self.min_keypoints) != self.min_keypoints or not 1 <= self.min_keypoints <= NUM_KEYPOINTS:
            raise ValueError(f"lift: min_keypoints must be an integer in 1..{NUM_KEYPOINTS}, got {self.min_keypoints}")
        if int(self.patch) != self.patch or self.patch < 1 or self.patch % 2 == 0:
            raise ValueError(f"lift: patch must be a positive odd number of pixels, got {self.patch}")
        for name in ("max_range", "depth_gate"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"lift: {name} must be a positive number of metres, got {value}")


def lift_people(
    detections: Sequence[PoseDetection],
    depth_m: np.ndarray,
    calib: Calibration,
    mount: CameraMount,
    params: LiftParams = LiftParams(),
    ids: Sequence[int] | None = None,
) -> list[Person]:
    """People in the world frame from one frame's pose detections.

    depth_m: the frame's depth in metres (0 or NaN = no reading), registered to colour when ``calib.depth`` is
    None, else in the depth camera's own grid (looked up sparsely, see ``sid.align``). ids: one per detection
    (default: the detection's index). Detections with fewer than ``params.min_keypoints`` lifted keypoints give no
    Person; the others get theta None when their facing cannot be told (see ``sid.orientation``).
    """
    if ids is not None and len(ids) != len(detections):
        raise ValueError(f"lift: {len(ids)} ids for {len(detections)} detections")
    if not detections:
        return []
    keypoints = np.stack([d.keypoints for d in detections])  # (P, 17, 2) colour pixels
    scores = np.stack([d.scores for d in detections])  # (P, 17)
    with np.errstate(invalid="ignore"):
        confident = (scores >= params.min_score) & np.isfinite(keypoints).all(axis=2)
    depth = np.full(scores.shape, np.nan)
    depth[confident] = depth_at_color_pixels(depth_m, keypoints[confident], calib, patch=params.patch)
    with np.errstate(invalid="ignore"):
        usable = confident & (depth > 0) & (depth <= params.max_range)
    # Median depth per person over its usable keypoints (unusable ones sort last as +inf; np.nanmedian is ~30x
    # slower on arrays this small).
    ordered = np.sort(np.where(usable, depth, np.inf), axis=1)
    count = np.count_nonzero(usable, axis=1)
    rows = np.arange(len(detections))
    median = 0.5 * (
        ordered[rows, np.maximum(count - 1, 0) // 2] + ordered[rows, np.minimum(count // 2, ordered.shape[1] - 1)]
    )
    with np.errstate(invalid="ignore"):
        usable &= np.abs(depth - median[:, None]) <= params.depth_gate
    world = np.full((*scores.shape, 3), np.nan)
    if usable.any():
        world[usable] = mount.camera_to_world(deproject(keypoints[usable], depth[usable], calib.color))
    counts = np.count_nonzero(usable, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        positions = np.where(usable[..., None], world[..., :2], 0.0).sum(axis=1) / counts[:, None]
    people = []
    for k in np.flatnonzero(counts >= params.min_keypoints).tolist():
        theta, quality = estimate_orientation(world[k])
        x, y = positions[k].tolist()
        people.append(Person(int(ids[k]) if ids is not None else k, x, y, theta, quality, world[k]))
    return people
