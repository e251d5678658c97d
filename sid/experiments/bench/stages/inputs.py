"""The fixed, seeded inputs several stages share: conversation circles of N people (world frame) and synthetic
RGB-D frames of the paper's layouts."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from sid.errors import InputError
from sid.experiments.bench.stages.core import (
    Context,
)
from sid.perception.people import Person

if TYPE_CHECKING:
    from sid.perception.frame import Frame
    from sid.perception.keypoints import PoseDetection
    from sid.synthetic import Scene

__all__ = ["CROWD_SPACING", "frame_scene", "grouping_scene", "synthetic_frames", "truth_detections"]

CROWD_SPACING = 2.4  # m between the centres of the circles of grouping_scene


def grouping_scene(n: int, seed: int = 0) -> list[Person]:
    """``n`` people in conversation circles facing their centre, world frame (metres, radians).

    Up to 6 people stand in one circle (radius 0.4 m for 2, i.e. 0.8 m apart as the paper's S1; 0.69 m for 3;
    0.8 m for 4-5; 0.85 m for 6: neighbours 0.8-0.85 m apart); more are split into circles of 4 whose centres lie
    2.4 m apart on a square grid: one crowd, strangers 0.8 m apart across neighbouring circles, one DBSCAN cluster
    at the ray methods' eps (2 m). Positions get 3 cm and facings 3 degrees of
    seeded Gaussian noise, so that rays cross at distinct points as they do on real estimates (exact rays all meet
    in one point).
    """
    if n < 1:
        raise InputError(f"bench: a grouping scene needs at least one person, got {n}")
    sizes = [n] if n <= 6 else [4] * (n // 4) + ([n % 4] if n % 4 else [])
    radius = {1: 0.4, 2: 0.4, 3: 0.69, 4: 0.8, 5: 0.8, 6: 0.85}
    rng = np.random.default_rng(seed)
    people: list[Person] = []
    columns = math.ceil(math.sqrt(len(sizes)))
    for k, size in enumerate(sizes):
        cx, cy = 2.5 + CROWD_SPACING * (k % columns), CROWD_SPACING * (k // columns)
        for j in range(size):
            angle = 2 * math.pi * j / size + 0.3
            x = cx + radius[size] * math.cos(angle) + rng.normal(0.0, 0.03)
            y = cy + radius[size] * math.sin(angle) + rng.normal(0.0, 0.03)
            theta = math.atan2(cy - y, cx - x) + rng.normal(0.0, math.radians(3.0))
            people.append(Person(len(people), x, y, theta, 1.0))
    return people


def frame_scene(n: int) -> Scene:
    """The synthetic scene of the per-frame pipeline: the paper's S1 (2 people), S3 (3), S5 (4), or 6 people on a
    1 m circle 3 m in front of the camera, facing its centre."""
    from sid.synthetic import Scene, ScenePerson, layout

    if n in (2, 3, 4):
        return layout({2: "S1", 3: "S3", 4: "S5"}[n])
    angles = [2 * math.pi * k / n + math.pi / n for k in range(n)]
    people = tuple(
        ScenePerson(k, 3.0 + math.cos(a), math.sin(a), math.atan2(-math.sin(a), -math.cos(a)))
        for k, a in enumerate(angles)
    )
    return Scene(f"circle{n}", people, (tuple(range(n)),))


def synthetic_frames(ctx: Context, n: int, count: int = 4) -> list[Frame]:
    """``count`` synthetic RGB-D frames (D435i depth 848x480 with noise, colour grid 1280x720) of ``n`` people."""

    def build() -> list[Frame]:
        from sid.synthetic import SyntheticCamera

        camera = SyntheticCamera(shaded_color=False)  # the colour image is not used: faster rendering
        scene = frame_scene(n)
        return [camera.capture(scene, index=i, seed=0) for i in range(count)]

    return ctx.cached(f"frames/{n}", build)


def truth_detections(frame: Frame) -> list[PoseDetection]:
    from sid.synthetic.pose import TruthPose

    return TruthPose()(frame)
