"""2D pose estimation: an ONNX pose model behind one call, RGB image in, people with COCO-17 keypoints out.

>>> estimator = load_pose_estimator("yolo11n-pose-256.onnx")
>>> detections = estimator(color_rgb)  # list[PoseDetection], keypoints in colour-image pixels (u, v)

The model contract (MoveNet MultiPose, MoveNet SinglePose, YOLO-pose) is read from the model's own signature;
see ``sid.perception.pose.contracts`` and docs/models.md.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sid.errors import InputError
from sid.perception.pose.base import Letterbox, PoseEstimator
from sid.perception.pose.contracts import (
    CONTRACTS,
    MOVENET_MULTIPOSE,
    MOVENET_SINGLEPOSE,
    YOLO_POSE,
    PoseModelError,
    detect_contract,
    supported_contracts_text,
)
from sid.perception.pose.movenet import MoveNetMultiPose, MoveNetSinglePose, multipose_input_size
from sid.perception.pose.session import PROVIDER_CHOICES, OnnxModel
from sid.perception.pose.yolo import YoloPose

__all__ = [
    "CONTRACTS",
    "Letterbox",
    "MoveNetMultiPose",
    "MoveNetSinglePose",
    "OnnxModel",
    "PROVIDER_CHOICES",
    "PoseEstimator",
    "PoseModelError",
    "YoloPose",
    "load_pose_estimator",
    "multipose_input_size",
    "supported_contracts_text",
]


def load_pose_estimator(
    path: str | Path,
    contract: str | None = None,
    threads: int | None = None,
    score_threshold: float | None = None,
    input_size: int | tuple[int, int] | str | None = None,
    iou_threshold: float | None = None,
    providers: str | Sequence[str] | None = None,
    spinning: bool = False,
    load_warnings: bool = False,
) -> MoveNetMultiPose | MoveNetSinglePose | YoloPose:
    """Open a pose model and wrap it in the estimator its contract needs.

    path: an .onnx file. contract: ``movenet_multipose``, ``movenet_singlepose`` or ``yolo_pose``; None reads it
    from the model's signature. threads: onnxruntime intra-op threads, an int >= 1 (default: physical cores); the
    thread pools do not spin-wait unless ``spinning`` (see ``sid.perception.pose.session``).
    score_threshold: minimum person score (default per model: 0.2 MoveNet, 0.25 YOLO; scores of converted models
    differ from the originals, so tune it per model file). input_size: only for models with dynamic height and
    width (MultiPose: long side in px, (h, w) or "paper"; SinglePose: side; YOLO: side or (h, w)).
    iou_threshold: YOLO NMS overlap (default 0.7). providers: ``"auto"`` (default: TensorRT, CUDA, OpenVINO when
    this onnxruntime offers them, then CPU), ``"cpu"``, ``"openvino"`` (needs ``pip install 'sid-social[openvino]'``) or
    a list of onnxruntime provider names; ``estimator.model.providers`` says what the session uses.
    load_warnings: let onnxruntime print the warnings of loading the model (e.g. deprecated attributes some
    exporters write; kept out by default).

    Raises PoseModelError (missing file, not ONNX, unsupported signature; the message lists the contracts and
    where such models come from), ValueError for options the model cannot take, a bad thread count or an unknown
    provider, and ``sid.distribution.MissingDependencyError`` for ``"openvino"`` when it is not installed.
    """
    model = OnnxModel(path, threads=threads, providers=providers, spinning=spinning, load_warnings=load_warnings)
    name = detect_contract(model.signature, contract, source=str(model.path))
    try:
        estimator = _estimator(model, name, score_threshold, input_size, iou_threshold)
        estimator(np.full((64, 64, 3), 128, np.uint8))  # a model whose signature fits but which fails when run
    except Exception as exc:
        if not type(exc).__module__.startswith("onnxruntime"):
            raise
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise PoseModelError(
            f"pose: {model.path}: the model fits the {name} contract but fails when run ({first[:300]}); "
            "export it with a fixed input size, or give input_size for its dynamic one"
        ) from None
    return estimator


def _estimator(
    model: OnnxModel,
    name: str,
    score_threshold: float | None,
    input_size: int | tuple[int, int] | str | None,
    iou_threshold: float | None,
) -> MoveNetMultiPose | MoveNetSinglePose | YoloPose:
    """The estimator of contract ``name`` over ``model`` (``load_pose_estimator``'s options)."""
    if iou_threshold is not None and name != YOLO_POSE:
        raise InputError(f"pose: iou_threshold applies to yolo_pose models only, this one is {name}")
    options: dict[str, Any] = {} if score_threshold is None else {"score_threshold": score_threshold}
    if name == MOVENET_MULTIPOSE:
        return MoveNetMultiPose(model, size=input_size, **options)
    if name == MOVENET_SINGLEPOSE:
        if isinstance(input_size, (str, tuple)):
            raise InputError(f"pose: a SinglePose input size is one side in pixels, got {input_size!r}")
        return MoveNetSinglePose(model, size=input_size, **options)
    if isinstance(input_size, str):
        raise InputError(f"pose: a YOLO input size is a side or (height, width) in pixels, got {input_size!r}")
    if iou_threshold is not None:
        options["iou_threshold"] = iou_threshold
    return YoloPose(model, size=input_size, **options)
