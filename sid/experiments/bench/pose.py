"""One pose-model call split into pre-processing, the model call (``session.run``) and post-processing (decoding,
thresholding, NMS for YOLO, mapping back to image pixels): the parts the ``pose/*`` benchmarks time
(``sid.experiments.bench.stages.networks``)."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

__all__ = ["timed_call"]


def timed_call(estimator: Any, image: np.ndarray) -> tuple[tuple[int, int, int], int]:
    """One whole-image call of a pose estimator on ``image`` (H, W, 3) RGB uint8, split into stages:
    ((preprocess, inference, postprocess) in ns, people found)."""
    t0 = time.perf_counter_ns()
    tensor, letterbox = estimator.preprocess(image)
    t1 = time.perf_counter_ns()
    output = estimator.infer(tensor)
    t2 = time.perf_counter_ns()
    people = estimator.decode(output, letterbox, image.shape[:2])
    t3 = time.perf_counter_ns()
    return (t1 - t0, t2 - t1, t3 - t2), len(people) if isinstance(people, list) else 1
