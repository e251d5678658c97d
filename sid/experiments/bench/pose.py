"""Timing of the pose stage, split into pre-processing, the model call (``session.run``) and post-processing.

Post-processing is decoding, thresholding, NMS (YOLO) and mapping back to image pixels. Every figure is the median
over ``runs`` repeats in milliseconds, after a few warm-up calls. For MoveNet SinglePose the crop loop (one model
call per person) is timed for each count in ``crop_counts``; the timing does not depend on what the crops show,
so without ``boxes`` the image is cut into that many vertical strips.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sid.experiments.bench.runner import RunSettings, measure_parts
from sid.perception.pose import MoveNetSinglePose, load_pose_estimator
from sid.perception.pose.base import check_boxes, check_color_image

__all__ = ["WARMUP", "bench_pose", "timed_call"]

WARMUP = 3


def _time_stages(stages: Callable[[], tuple[int, int, int]], runs: int) -> dict[str, float]:
    """Median milliseconds of each part of ``stages()`` ((preprocess, inference, postprocess) in ns) and of their
    sum, over ``runs`` timed calls after ``WARMUP`` untimed ones (``sid.experiments.bench.runner``)."""

    def parts() -> dict[str, float]:
        pre, infer, post = stages()
        return {"preprocess_ms": pre / 1e6, "inference_ms": infer / 1e6, "postprocess_ms": post / 1e6,
                "total_ms": (pre + infer + post) / 1e6}  # fmt: skip

    settings = RunSettings(warmup=WARMUP, min_runs=runs, max_runs=runs, budget_s=1.0)  # exactly ``runs`` calls
    return {name: stats.median_ms for name, stats in measure_parts(parts, settings).items()}


def _strips(image_hw: Sequence[int], count: int) -> np.ndarray:
    h, w = image_hw
    edges = np.linspace(-0.5, w - 0.5, count + 1)
    return np.stack([edges[:-1], np.full(count, -0.5), edges[1:], np.full(count, h - 0.5)], axis=1)


def timed_call(estimator: Any, image: np.ndarray, box: np.ndarray | None = None) -> tuple[tuple[int, int, int], int]:
    """One call split into stages: ((preprocess, inference, postprocess) in ns, people found). ``box``: the crop
    (u_min, v_min, u_max, v_max) of a SinglePose call; None: the whole image."""
    t0 = time.perf_counter_ns()
    tensor, letterbox = estimator.preprocess(image) if box is None else estimator.preprocess(image, box)
    t1 = time.perf_counter_ns()
    output = estimator.infer(tensor)
    t2 = time.perf_counter_ns()
    people = estimator.decode(output, letterbox, image.shape[:2])
    t3 = time.perf_counter_ns()
    return (t1 - t0, t2 - t1, t3 - t2), len(people) if isinstance(people, list) else 1


def bench_pose(
    model_path: str | Path,
    image: np.ndarray,
    runs: int = 50,
    *,
    boxes: np.ndarray | None = None,
    crop_counts: Sequence[int] = (2, 3, 4, 6),
    threads: int | None = None,
    contract: str | None = None,
) -> dict[str, Any]:
    """Median per-stage times (ms) of one pose model on ``image`` (H, W, 3) RGB uint8.

    Returns ``{"model", "contract", "input_size", "threads", "providers", "runs", "image": {...}, "crops": {...}}``
    where ``image`` times the whole-image call (``preprocess_ms``, ``inference_ms``, ``postprocess_ms``,
    ``total_ms``, ``people`` found) and ``crops`` (SinglePose only) maps each people count to the same times
    summed over that many crops, plus ``per_crop_total_ms``. ``boxes`` (N, 4) are the person boxes to crop,
    repeated as needed to reach each count.
    """
    if runs < 1:
        raise ValueError(f"bench: runs must be >= 1, got {runs}")
    image = check_color_image(image)
    estimator = load_pose_estimator(model_path, contract=contract, threads=threads)
    image_hw = image.shape[:2]
    found: list[int] = []

    def whole_image() -> tuple[int, int, int]:
        times, people = timed_call(estimator, image)
        found.append(people)
        return times

    result: dict[str, Any] = {
        "model": str(model_path),
        "contract": estimator.contract,
        "input_size": estimator.input_size or estimator.input_size_for(image_hw),
        "threads": estimator.model.threads,
        "providers": estimator.model.providers,
        "runs": runs,
        "image": _time_stages(whole_image, runs) | {"people": found[-1]},
    }
    if isinstance(estimator, MoveNetSinglePose):
        result["crops"] = {n: _bench_crops(estimator, image, boxes, n, runs) for n in crop_counts}
    return result


def _bench_crops(
    estimator: MoveNetSinglePose, image: np.ndarray, boxes: np.ndarray | None, count: int, runs: int
) -> dict[str, float]:
    if count < 1:
        raise ValueError(f"bench: crop counts must be >= 1, got {count}")
    if boxes is None or len(boxes) == 0:
        chosen = _strips(image.shape[:2], count)
    else:
        chosen = check_boxes(boxes)[np.arange(count) % len(boxes)]

    def crop_loop() -> tuple[int, int, int]:
        pre, infer, post = zip(*(timed_call(estimator, image, box)[0] for box in chosen), strict=True)
        return sum(pre), sum(infer), sum(post)

    times = _time_stages(crop_loop, runs)
    return times | {"per_crop_total_ms": times["total_ms"] / count}
