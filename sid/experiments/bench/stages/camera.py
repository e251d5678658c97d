"""``align/*``, ``lift/4``, ``pca/4``, ``synthetic/render`` and ``synthetic/noise``: depth alignment, lifting and
facing on synthetic D435i frames, and rendering those frames."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from sid.errors import InputError
from sid.experiments.bench.runner import measure
from sid.experiments.bench.stages.core import (
    PAPER_LIFT_MS,
    Benchmark,
    Context,
    Records,
    record,
)
from sid.experiments.bench.stages.inputs import frame_scene, synthetic_frames, truth_detections

if TYPE_CHECKING:
    from sid.perception.align import SplatMode

__all__ = ["ALIGN_MODES", "depth_benchmarks", "render_benchmarks"]

ALIGN_MODES: tuple[SplatMode, ...] = ("rectangle", "point")


def _bench_align(mode: SplatMode) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from sid.perception.align import Aligner

        frame = synthetic_frames(ctx, 4)[0]
        aligner = Aligner(frame.calibration, mode)  # built once per stream, as a user does
        stats = measure(lambda: aligner(frame.depth), ctx.settings)
        kd, kc = frame.calibration.depth, frame.calibration.color
        if kd is None:  # unreachable: Aligner refuses a calibration without depth intrinsics
            raise InputError("bench: align needs depth intrinsics; the frame's depth is registered to colour")
        filled = float(np.count_nonzero(aligner(frame.depth)) / (kc.width * kc.height))
        size = f"{kd.width}x{kd.height} -> {kc.width}x{kc.height}"
        return {f"align/{mode}": record(stats, size=size, filled_fraction=round(filled, 3))}

    return run


def _bench_sparse_depth(ctx: Context) -> Records:
    from sid.perception.align import depth_at_color_pixels

    frame = synthetic_frames(ctx, 4)[0]
    pixels = np.concatenate([d.keypoints for d in truth_detections(frame)])
    stats = measure(lambda: depth_at_color_pixels(frame.depth, pixels, frame.calibration), ctx.settings)
    found = int(np.count_nonzero(np.isfinite(depth_at_color_pixels(frame.depth, pixels, frame.calibration))))
    return {"align/sparse_4x17": record(stats, keypoints=len(pixels), with_depth=found)}


def _bench_window_depth(ctx: Context) -> Records:
    from sid.perception.align import depth_at_color_pixels

    frame = synthetic_frames(ctx, 4)[0]
    pixels = np.concatenate([d.keypoints for d in truth_detections(frame)])

    def lookup(search: str) -> np.ndarray:
        return depth_at_color_pixels(frame.depth, pixels, frame.calibration, search=search)  # type: ignore[arg-type]

    stats = measure(lambda: lookup("window"), ctx.settings)
    window, exact = lookup("window"), lookup("exact")
    both = np.isfinite(window) & np.isfinite(exact)
    diff_mm = float(np.median(np.abs(window - exact)[both]) * 1e3) if both.any() else None
    return {
        "align/window_4x17": record(
            stats,
            keypoints=len(pixels),
            with_depth=int(np.count_nonzero(np.isfinite(window))),
            median_diff_to_exact_mm=diff_mm,
            ratio_to="align/sparse_4x17",
        )  # fmt: skip
    }


def _bench_lift(ctx: Context) -> Records:
    from sid.perception.lifting import LiftParams, lift_people
    from sid.perception.mount import CameraMount

    frame = synthetic_frames(ctx, 4)[0]
    detections, mount, params = truth_detections(frame), CameraMount(), LiftParams()
    stats = measure(lambda: lift_people(detections, frame.depth, frame.calibration, mount, params), ctx.settings)
    people = lift_people(detections, frame.depth, frame.calibration, mount, params)
    facing = sum(p.theta is not None for p in people)
    return {"lift/4": record(stats, people=len(people), with_facing=facing, paper_ms=PAPER_LIFT_MS[4])}


def _bench_pca(ctx: Context) -> Records:
    from sid.perception.orientation import estimate_orientations

    frame = synthetic_frames(ctx, 4)[0]
    keypoints = np.array([p.keypoints_world for p in frame.truth.people])  # (4, 17, 3)
    stats = measure(lambda: estimate_orientations(keypoints), ctx.settings)
    return {"pca/4": record(stats, people=len(keypoints))}


def _bench_render(fresh: bool) -> Callable[[Context], Records]:
    """``synthetic/render``: one synthetic RGB-D frame rendered afresh (``sid.synthetic.SyntheticCamera.capture``
    after ``forget_renders``: ray casting, shaded colour, D435i depth noise, truth); ``synthetic/noise``: the same
    capture on the camera's kept render of the still scene (depth and keypoint noise and truth only)."""

    def run(ctx: Context) -> Records:
        from sid.synthetic import SyntheticCamera

        camera, scene = SyntheticCamera(), frame_scene(4)
        counter = iter(range(10**9))

        def capture() -> None:
            if fresh:
                camera.forget_renders()
            camera.capture(scene, index=next(counter), seed=0)

        stats = measure(capture, ctx.settings)
        name = "synthetic/render" if fresh else "synthetic/noise"
        return {name: record(stats, scene=scene.name, people=len(scene.people))}

    return run


def depth_benchmarks() -> list[Benchmark]:
    """Alignment, the depth lookups at keypoints, lifting and the PCA facing, in report order."""
    items = [
        Benchmark(f"align/{mode}", f"Aligner ({mode} splat), full frame", _bench_align(mode)) for mode in ALIGN_MODES
    ]
    return items + [
        Benchmark("align/sparse_4x17", "depth_at_color_pixels, 4 x 17 keypoints", _bench_sparse_depth),
        Benchmark(
            "align/window_4x17",
            "depth_at_color_pixels(search='window'), 4 x 17 keypoints",
            _bench_window_depth,
            needs=("align/sparse_4x17",),
        ),  # fmt: skip
        Benchmark("lift/4", "lift_people (keypoint depth, 3D, position, PCA facing), 4 people", _bench_lift),
        Benchmark("pca/4", "estimate_orientations (PCA facing), 4 people at once", _bench_pca),
    ]


def render_benchmarks() -> list[Benchmark]:
    """Rendering one synthetic RGB-D frame (afresh, and on a kept render)."""
    return [
        Benchmark("synthetic/render", "SyntheticCamera.capture rendered afresh, 4 people", _bench_render(True)),
        Benchmark(
            "synthetic/noise", "SyntheticCamera.capture on a kept render (noise, truth), 4 people", _bench_render(False)
        ),
    ]
