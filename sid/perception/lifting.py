"""From 2D pose detections and depth to people in the world frame (the paper's steps 2-4).

Per detection: each confident keypoint takes the depth of its colour pixel
(``sid.perception.align.depth_at_color_pixels``,
robust to holes and silhouette edges), is deprojected with the colour intrinsics K_c (d * K_c^-1 [u v 1]) and moved
to the world frame with the camera mount. Keypoints without a valid depth are dropped, never placed at the camera,
and so are keypoints whose depth is far from their person's (``depth_gate``) or belongs to a person standing in front
(``occluder_gap``). Position = mean of the lifted keypoints' world x, y; facing =
``sid.perception.orientation.estimate_orientation`` (``estimate_orientations``: everyone at once).

A depth camera sees the body's surface, not its joints. Two corrections, both along each keypoint's viewing ray
(its pixel is kept), turn surface readings into points inside the body:

1. **Surface offset** (``LiftParams.surface_offset``): joints lie inside limbs and torso, about half their
   front-back thickness behind the skin, and the head's centre about half a head length behind the face; every
   keypoint is pushed that far further along its ray, so that lifted keypoints are points of the body's interior
   (joint centres, the head's mid-plane), which is what the position (their mean) and the body plane need.
2. **Far-side completion** (``LiftParams.complete_far_side``): in a side view the far shoulder, hip, ear, ... are
   hidden behind the person's own body; a pose model still places them (it knows the body's shape) with a lower
   score, but their pixels show the near side of the body, whose depth is tens of centimetres too near. The body
   plane then turns towards the camera and the front/back order of left and right collapses. A left/right pair is
   taken as *collapsed* when its two keypoints lie closer in 3D than ``min_pair_fraction`` of their anthropometric
   separation W (the joints of a pair cannot come closer than that: the depth of one is wrong), and its lower-score
   keypoint is then taken as the hidden one when its score is at least ``far_side_score_gap`` below its partner's.
   That keypoint keeps its ray and is placed behind its partner, at the depth where the pair is W apart in 3D:
   sqrt(W^2 - w^2) behind the partner's foot point on the ray, with w the partner's distance from the ray. Roots
   with a fixed separation: shoulders, hips, ears (W from ``sid.perception.orientation``). Elbows and wrists follow the
   shoulders, knees and ankles the hips: a follower scoring ``far_side_score_gap`` below its partner is put at
   least as far behind its partner as its root was put behind its own (never pulled nearer). Completed keypoints
   are reported as inferred to the orientation estimate, which counts them less as left/right evidence. Without a
   clear score difference a collapsed pair is left alone (and the orientation quality stays low).

Frames: camera optical (x right, y down, z forward) -> world (REP-103: x forward, y left, z up, origin on the
ground below the camera; see ``sid.perception.mount``). Units: metres, radians.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sid.checks import check_limit, check_number, check_numbers, check_whole
from sid.errors import InputError
from sid.perception.align import Search, depth_at_color_pixels
from sid.perception.camera import Calibration, pixel_rays
from sid.perception.keypoints import KP, NUM_KEYPOINTS, PoseDetection
from sid.perception.mount import CameraMount
from sid.perception.orientation import EAR_SEPARATION, HIP_SEPARATION, SHOULDER_SEPARATION, estimate_orientations
from sid.perception.people import Person

__all__ = ["LOOKUP_RANGE", "LiftParams", "lift_people"]

LOOKUP_RANGE = (0.1, 10.0)
"""Readings (m) a keypoint's depth lookup always accepts, whatever the lift's range: a depth camera's span (a D435
sees from about 0.1 m; beyond 10 m its readings are noise). ``LiftParams.min_range`` / ``max_range`` gate the looked-up
keypoints afterwards."""

# Far-side completion. Root keypoints and their partner a fixed separation away, as (root, partner): shoulders,
# hips, ears (``widths`` order), left roots then right ones.
_ROOT_PAIRS = tuple(
    (KP[f"{side}_{part}"], KP[f"{other}_{part}"])
    for side, other in (("left", "right"), ("right", "left"))
    for part in ("shoulder", "hip", "ear")
)
# Followers of a root keypoint, each with its partner (as (follower, partner)): the arm hangs from the shoulder, the
# leg from the hip; ears have none.
_FOLLOWERS = {
    KP[f"{side}_{root}"]: tuple((KP[f"{side}_{part}"], KP[f"{other}_{part}"]) for part in parts)
    for side, other in (("left", "right"), ("right", "left"))
    for root, parts in (("shoulder", ("elbow", "wrist")), ("hip", ("knee", "ankle")))
}


@dataclass(frozen=True)
class LiftParams:
    """How keypoints become 3D points (metres). Measurements behind the defaults: docs/parameters.md.

    min_score: a keypoint is used when its score is at least this. 0.3 is a common visibility cut for MoveNet and
      YOLO-pose keypoints, but scores are model-specific (float ONNX conversions score differently from the int8
      TFLite originals): set it per model.
    min_keypoints: a detection with fewer lifted keypoints gives no Person. 3: fewer cannot be placed reliably
      (one occluded limb at a wrong depth would decide the position) and cannot give a facing direction.
    patch: side (pixels, odd) of the depth window read around each keypoint. 5, as the paper's authors did.
    depth_search: how keypoint depth is found in unregistered depth (``sid.perception.align.depth_at_color_pixels``'s
      ``search``). "window" (default): fixed-point steps to the depth pixel each keypoint sees and the depth window
      around it, several times faster than "exact" and within millimetres of it at the median (docs/benchmarks.md,
      "Depth at the keypoints"); the far outliers (a window that reads the wall beside a silhouette) are what
      ``depth_gate`` drops. "exact": the splat search, equal to aligning the whole frame.
    min_range: keypoints nearer than this to the camera (m, optical z, above 0) are dropped (readings down to it are
      looked up, and down to ``LOOKUP_RANGE``'s). 0.2: a D435's minimum depth at 848x480 is
      about 0.2 m, so a nearer reading is an artefact or a corrupt depth image (1 mm everywhere would otherwise
      place people 7 cm from the lens).
    max_range: keypoints farther than this from the camera (m, optical z) are dropped (readings up to it are looked
      up, and up to ``LOOKUP_RANGE``'s). 6.0: D435-class depth
      noise grows with range squared (~2 % at 2 m, ~20 cm at 6 m), beyond which body orientation is noise.
    depth_gate: keypoints whose depth differs from the person's median keypoint depth by more than this (m) are
      dropped. 0.6: a standing body spans ~0.3 m in depth even in side view; a keypoint beyond that read the wall
      or a person behind (a keypoint on the silhouette edge, or a mislocalised wrist).
    occluder_gap: a keypoint inside the box of another person whose median keypoint depth is more than this (m)
      nearer, with a depth closer to that person's median than to its own person's, read the person in front (an
      arm or leg hidden behind them, a silhouette edge) and is dropped. 0.2: about a body's depth (chest depth
      0.20-0.25 m); people whose medians differ less stand side by side, where the closer median would be a coin
      toss. ``math.inf`` turns it off.
    surface_offset: how far (m) a keypoint's point inside the body lies behind the surface the camera sees, added
      along every keypoint's viewing ray. 0.07: about half the front-back thickness of an adult around the joints
      (chest depth 0.20-0.25 m, upper arm and thigh diameters 0.09-0.15 m, clothes 1-2 cm; the head's centre lies
      ~0.1 m behind the face). 0 turns it off.
    complete_far_side: place the hidden far side of a collapsed left/right pair behind its partner (module
      docstring). shoulder_separation, hip_separation, ear_separation: the pairs' 3D separation W (m), adult
      values from ``sid.perception.orientation`` (sources there); lower them for children.
    min_pair_fraction: a pair closer in 3D than this fraction of W is collapsed. 0.7 (0.24 m for shoulders): the
      narrowest adults (biacromial breadth 0.325 m, 5th percentile of women) put their shoulder keypoints ~0.26 m
      apart, and depth noise adds a few centimetres either way, while a far side that read the near side's surface
      leaves the pair much closer.
    far_side_score_gap: the lower-score keypoint of a collapsed pair is the hidden one when its score is at least
      this much below its partner's. 0.1: pose models score both visible shoulders or hips within a few hundredths
      of each other and a hidden far side tenths lower. A model that scores its guesses as high as what it sees
      gets no completion: side views then fail as without it.
    """

    min_score: float = 0.3
    min_keypoints: int = 3
    patch: int = 5
    depth_search: Search = "window"
    min_range: float = 0.2
    max_range: float = 6.0
    depth_gate: float = 0.6
    occluder_gap: float = 0.2
    surface_offset: float = 0.07
    complete_far_side: bool = True
    shoulder_separation: float = SHOULDER_SEPARATION
    hip_separation: float = HIP_SEPARATION
    ear_separation: float = EAR_SEPARATION
    min_pair_fraction: float = 0.7
    far_side_score_gap: float = 0.1

    def __post_init__(self) -> None:
        check_number("lift", "min_score", self.min_score, low=0, high=1)
        check_whole("lift", "min_keypoints", self.min_keypoints, low=1, high=NUM_KEYPOINTS)
        if check_whole("lift", "patch", self.patch, low=1) % 2 == 0:
            raise InputError(f"lift: patch must be a positive odd number of pixels, got {self.patch}")
        if self.depth_search not in ("exact", "window"):
            raise InputError(f"lift: depth_search must be 'exact' or 'window', got {self.depth_search!r}")
        check_number("lift", "occluder_gap", self.occluder_gap, low=0, allow_inf=True, unit="metres")  # inf: off
        check_number("lift", "min_range", self.min_range, low=0, low_open=True, unit="metres")
        if self.min_range >= self.max_range:
            raise InputError(f"lift: min_range ({self.min_range} m) must be below max_range ({self.max_range} m)")
        metres = ("max_range", "depth_gate", "shoulder_separation", "hip_separation", "ear_separation")
        check_numbers("lift", self, metres, low=0, low_open=True, unit="metres")
        check_number("lift", "surface_offset", self.surface_offset, low=0, high=0.5, high_open=True, unit="metres")
        check_number("lift", "min_pair_fraction", self.min_pair_fraction, low=0, high=1, low_open=True)
        check_number("lift", "far_side_score_gap", self.far_side_score_gap, low=0, high=1)


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
    None, else in the depth camera's own grid (looked up sparsely, see ``sid.perception.align``). ids: one per detection
    (default: the detection's index). Detections with fewer than ``params.min_keypoints`` lifted keypoints give no
    Person; the others get theta None when their facing cannot be told (see ``sid.perception.orientation``). Keypoints
    are corrected from the body's surface to its joints (module docstring).
    """
    if ids is not None and len(ids) != len(detections):
        raise InputError(f"lift: {len(ids)} ids for {len(detections)} detections")
    if not detections:
        return []
    check_limit("lift: detections", len(detections), "detections", "detections")  # (P, P, 17) arrays below
    # np.array of a list of equal-shape arrays stacks them, with less overhead than np.stack.
    keypoints = np.array([d.keypoints for d in detections])  # (P, 17, 2) colour pixels
    scores = np.array([d.scores for d in detections])  # (P, 17)
    confident = scores >= params.min_score  # (comparisons with NaN: False; a NaN keypoint gets no depth)
    depth = np.full(scores.shape, np.nan)
    depth[confident] = depth_at_color_pixels(
        depth_m,
        keypoints[confident],
        calib,
        patch=params.patch,
        search=params.depth_search,
        # Readings the lookup may use: the sensor's span, widened to the lift's range but never cut to it, so that a
        # person just beyond max_range reads beyond it and is gated below (readings cut at max_range would leave the
        # nearer half of their noise, a person placed just inside).
        depth_min=min(params.min_range, LOOKUP_RANGE[0]),
        depth_max=max(params.max_range, LOOKUP_RANGE[1]),
    )
    usable = (depth >= params.min_range) & (depth <= params.max_range)  # NaN (not confident, no reading): False
    # Median depth per person over its usable keypoints (unusable ones sort last as +inf; np.nanmedian is much
    # slower on arrays this small), picked from the sorted rows in Python (a few people: cheaper than numpy).
    ordered = np.sort(np.where(usable, depth, np.inf), axis=1).tolist()
    middle = [
        0.5 * (row[max(count - 1, 0) // 2] + row[min(count // 2, NUM_KEYPOINTS - 1)])
        for row, count in zip(ordered, usable.sum(axis=1).tolist(), strict=True)
    ]
    median = np.array(middle)
    usable &= np.abs(depth - median[:, None]) <= params.depth_gate
    if len(detections) > 1 and math.isfinite(params.occluder_gap):
        boxes = np.array([d.box for d in detections])
        usable &= ~_reads_someone_in_front(keypoints, depth, median, boxes, params.occluder_gap)

    # Each keypoint's viewing ray (camera frame, through K_c^-1 [u v 1] = (ray_x, ray_y, 1)) and its range along it
    # (m; NaN where unusable); depth z and range r: r = z * |(ray_x, ray_y, 1)|.
    ray = np.stack(pixel_rays(keypoints[..., 0], keypoints[..., 1], calib.color), axis=-1)  # (P, 17, 2)
    ray_x, ray_y = ray[..., 0], ray[..., 1]
    norm = np.sqrt(ray_x * ray_x + ray_y * ray_y + 1.0)
    ranges = np.where(usable, depth * norm + params.surface_offset, np.nan)
    inferred = np.zeros(scores.shape, dtype=bool)
    if params.complete_far_side:
        _complete_far_side(ray, norm, ranges, scores, inferred, params)

    world = np.full((*scores.shape, 3), np.nan)
    z = ranges[usable] / norm[usable]
    camera = np.empty((len(z), 3))  # (x, y, z) = z * (ray_x, ray_y, 1)
    camera[:, :2] = ray[usable] * z[:, None]
    camera[:, 2] = z
    lifted = mount.camera_to_world(camera)  # the usable keypoints, person by person
    world[usable] = lifted
    counts = usable.sum(axis=1).tolist()
    placed = [k for k, count in enumerate(counts) if count >= params.min_keypoints]
    facings = estimate_orientations(world[placed], inferred[placed])
    # Position: the mean of the lifted keypoints' x, y, summed in keypoint order on Python floats (a few people).
    ground = lifted[:, :2].tolist()
    ends = list(itertools.accumulate(counts))
    people = []
    for k, (theta, quality) in zip(placed, facings, strict=True):
        x = y = 0.0
        for point_x, point_y in ground[ends[k] - counts[k] : ends[k]]:
            x += point_x
            y += point_y
        people.append(
            Person(int(ids[k]) if ids is not None else k, x / counts[k], y / counts[k], theta, quality, world[k])
        )
    return people


def _reads_someone_in_front(
    keypoints: np.ndarray, depth: np.ndarray, median: np.ndarray, boxes: np.ndarray, gap: float
) -> np.ndarray:
    """(P, 17) bool: keypoints that read a person in front of theirs (``LiftParams.occluder_gap``).

    keypoints: (P, 17, 2) colour pixels; depth: (P, 17) m (NaN: none); median: (P,) each person's median keypoint
    depth (m); boxes: (P, 4) (u_min, v_min, u_max, v_max). Pairs (i, j) below: keypoints of i, person j.
    """
    in_front = median[None, :] < median[:, None] - gap  # (P, P)
    if not in_front.any():
        return np.zeros(depth.shape, dtype=bool)
    u, v = keypoints[:, None, :, 0], keypoints[:, None, :, 1]  # (P, 1, 17)
    box = boxes[None, :, :, None]  # (1, P, 4, 1)
    inside = (u >= box[:, :, 0]) & (u <= box[:, :, 2]) & (v >= box[:, :, 1]) & (v <= box[:, :, 3])  # (P, P, 17)
    # Closer to j's median than to i's, j in front: nearer than the midpoint of the two medians (-inf: j not in front).
    limit = np.where(in_front, 0.5 * (median[:, None] + median[None, :]), -np.inf)
    return np.asarray((inside & (depth[:, None, :] < limit[:, :, None])).any(axis=1))


def _complete_far_side(
    ray: np.ndarray, norm: np.ndarray, ranges: np.ndarray, scores: np.ndarray, inferred: np.ndarray, params: LiftParams
) -> None:
    """Far-side completion (module docstring), in place on ``ranges`` (P, 17) and ``inferred`` (P, 17).

    ray: (P, 17, 2) viewing rays (ray_x, ray_y, 1) in the camera frame as (ray_x, ray_y); norm: (P, 17) their
    lengths; ranges: metres along the rays, NaN where unusable; scores: (P, 17). The few candidate pairs are worked
    out on Python floats (cheaper than numpy on a handful of values), each new range computed from the ranges
    before any is written.
    """
    gap = params.far_side_score_gap
    widths = (params.shoulder_separation, params.hip_separation, params.ear_separation)  # ``_ROOT_PAIRS`` order
    # Candidates: a root keypoint scoring clearly lower than its partner (the hidden one, if the pair collapsed).
    score_rows = scores.tolist()
    candidates = [
        (person, k, far, near)
        for person, row in enumerate(score_rows)
        for k, (far, near) in enumerate(_ROOT_PAIRS)
        if row[far] <= row[near] - gap
    ]
    if not candidates:
        return
    rays, lengths, old_ranges = ray.tolist(), norm.tolist(), ranges.tolist()
    completed = []  # (person, keypoint, range along its ray, how far behind its partner's range)
    for person, k, far, near in candidates:
        (far_x, far_y), (near_x, near_y) = rays[person][far], rays[person][near]
        far_range, near_range = old_ranges[person][far], old_ranges[person][near]
        # u . P: the partner's point P projected on the far keypoint's unit ray u.
        foot = (far_x * near_x + far_y * near_y + 1.0) / (lengths[person][far] * lengths[person][near]) * near_range
        width = widths[k % len(widths)]
        limit = params.min_pair_fraction * width
        # |far - near|^2 = r_far^2 - 2 r_far (u . P) + |P|^2; NaN (a keypoint missing) compares False: not completed.
        if far_range * (far_range - 2 * foot) + near_range * near_range < limit * limit:
            # The hidden keypoint at W from its partner, behind it: t = u.P + sqrt(W^2 - w^2), w^2 = |P|^2 - (u.P)^2.
            target = foot + math.sqrt(max(width * width - near_range * near_range + foot * foot, 0.0))
            completed.append((person, far, target, target - near_range))
    # Followers on the hidden side scoring clearly lower than their partner: at least as far behind their partner
    # as the root is behind its own (fmax: the keypoint's own range where its partner has none; a follower without
    # a range of its own stays unusable whatever its range). The followers and their partners are no roots.
    moved = []
    for person, root, _, behind in completed:
        for own, partner in _FOLLOWERS.get(root, ()):
            if score_rows[person][own] <= score_rows[person][partner] - gap:
                current, reach = old_ranges[person][own], old_ranges[person][partner] + behind
                placed = reach if math.isnan(current) else current if math.isnan(reach) else max(current, reach)
                moved.append((person, own, placed, placed > current))
    for person, far, target, _ in completed:
        ranges[person, far] = target
        inferred[person, far] = True
    for person, own, placed, further in moved:
        ranges[person, own] = placed
        inferred[person, own] = further
