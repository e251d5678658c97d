"""Model contracts: which input/output signature each supported pose-model family has, and how to tell them apart.

A contract is recognised from the ONNX model's own signature (input and output dtypes and shapes; names vary with
the converter and are not relied on). Dynamic dimensions (``None``) match anything. The contracts exclude each
other (MoveNet takes integers, YOLO floats; MultiPose answers a rank-3 tensor, SinglePose a rank-4 one), so at most
one fits a model; naming a contract explicitly only adds a check.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sid.errors import SidError

__all__ = [
    "CONTRACTS",
    "Contract",
    "MOVENET_MULTIPOSE",
    "MOVENET_SINGLEPOSE",
    "ModelSignature",
    "PoseModelError",
    "TensorSpec",
    "YOLO_POSE",
    "detect_contract",
    "fixed_hw",
    "supported_contracts_text",
    "yolo_layout",
]

MOVENET_MULTIPOSE = "movenet_multipose"
MOVENET_SINGLEPOSE = "movenet_singlepose"
YOLO_POSE = "yolo_pose"

_ORT_DTYPES: dict[str, np.dtype] = {
    "tensor(float)": np.dtype(np.float32),
    "tensor(float16)": np.dtype(np.float16),
    "tensor(double)": np.dtype(np.float64),
    "tensor(uint8)": np.dtype(np.uint8),
    "tensor(int8)": np.dtype(np.int8),
    "tensor(int32)": np.dtype(np.int32),
    "tensor(int64)": np.dtype(np.int64),
}


class PoseModelError(SidError, ValueError):
    """A pose model file that cannot be used: missing, not ONNX, or with a signature no contract matches."""


@dataclass(frozen=True)
class TensorSpec:
    """One model input or output: name, numpy dtype (None if not a plain tensor), shape (None = dynamic)."""

    name: str
    dtype: np.dtype | None
    shape: tuple[int | None, ...]

    def __str__(self) -> str:
        dims = ", ".join("?" if d is None else str(d) for d in self.shape)
        return f"{self.name}: {self.dtype if self.dtype is not None else 'non-tensor'} [{dims}]"


@dataclass(frozen=True)
class ModelSignature:
    """The inputs and outputs of an ONNX model, as onnxruntime reports them."""

    inputs: tuple[TensorSpec, ...]
    outputs: tuple[TensorSpec, ...]

    @classmethod
    def from_session(cls, session: Any) -> ModelSignature:  # an onnxruntime.InferenceSession
        return cls(tuple(_spec(a) for a in session.get_inputs()), tuple(_spec(a) for a in session.get_outputs()))

    def __str__(self) -> str:
        ins = "; ".join(str(s) for s in self.inputs) or "none"
        outs = "; ".join(str(s) for s in self.outputs) or "none"
        return f"inputs: {ins} -> outputs: {outs}"


@dataclass(frozen=True)
class Contract:
    """A supported model family: its signature in words, where users get such a model, and a signature check."""

    name: str
    signature: str
    source: str
    mismatch: Callable[[ModelSignature], str | None]
    """Returns None when the signature fits this contract, else the reason it does not."""


def _spec(arg: Any) -> TensorSpec:  # an onnxruntime.NodeArg
    shape = tuple(d if isinstance(d, int) and d > 0 else None for d in (arg.shape or ()))
    return TensorSpec(arg.name, _ORT_DTYPES.get(arg.type), shape)


def fixed_hw(dims: Sequence[int | None]) -> tuple[int, int] | None:
    """An input's two spatial dimensions (height, width) in pixels, or None when both are dynamic.

    The contracts refuse an input with one side fixed and the other dynamic, so ``dims`` has both or neither.
    """
    height, width = dims[0], dims[1]
    return None if height is None or width is None else (height, width)


def _half_dynamic(height: int | None, width: int | None) -> str | None:
    if (height is None) == (width is None):
        return None
    dims = " x ".join("?" if d is None else str(d) for d in (height, width))
    return (
        f"input height x width {dims} has one side fixed and the other dynamic; export the model with both "
        "fixed or both dynamic"
    )


def _dim_is(dim: int | None, *allowed: int) -> bool:
    return dim is None or dim in allowed


def _one_io(sig: ModelSignature) -> str | None:
    if len(sig.inputs) != 1 or len(sig.outputs) < 1:
        return f"needs exactly one input and an output, has {len(sig.inputs)} inputs and {len(sig.outputs)} outputs"
    return None


def _nhwc_image(spec: TensorSpec, dtypes: tuple[type, ...]) -> str | None:
    if spec.dtype not in [np.dtype(d) for d in dtypes]:
        return f"input dtype {spec.dtype}, expected {' or '.join(np.dtype(d).name for d in dtypes)}"
    if len(spec.shape) != 4 or not _dim_is(spec.shape[0], 1) or not _dim_is(spec.shape[3], 3):
        return f"input shape {list(spec.shape)}, expected [1, H, W, 3]"
    return _half_dynamic(spec.shape[1], spec.shape[2])


def _multipose_mismatch(sig: ModelSignature) -> str | None:
    if reason := _one_io(sig) or _nhwc_image(sig.inputs[0], (np.int32,)):
        return reason
    out = sig.outputs[0]
    if out.dtype != np.float32 or len(out.shape) != 3 or not all(map(_dim_is, out.shape, (1, 6, 56))):
        return f"output {out.dtype} {list(out.shape)}, expected float32 [1, 6, 56]"
    h, w = sig.inputs[0].shape[1:3]
    if any(d is not None and d % 32 for d in (h, w)):
        return f"input height and width {h}x{w} must be multiples of 32"
    return None


def _singlepose_mismatch(sig: ModelSignature) -> str | None:
    if reason := _one_io(sig) or _nhwc_image(sig.inputs[0], (np.uint8, np.int32)):
        return reason
    out = sig.outputs[0]
    if out.dtype != np.float32 or len(out.shape) != 4 or not all(map(_dim_is, out.shape, (1, 1, 17, 3))):
        return f"output {out.dtype} {list(out.shape)}, expected float32 [1, 1, 17, 3]"
    return None


def yolo_layout(spec: TensorSpec) -> str | None:
    """ "nchw" or "nhwc" for a YOLO image input, from where its 3-channel axis is; None if neither fits."""
    if len(spec.shape) != 4 or not _dim_is(spec.shape[0], 1):
        return None
    if spec.shape[1] == 3 and spec.shape[3] != 3:
        return "nchw"
    if spec.shape[3] == 3 and spec.shape[1] != 3:
        return "nhwc"
    return None


def _yolo_mismatch(sig: ModelSignature) -> str | None:
    if reason := _one_io(sig):
        return reason
    spec = sig.inputs[0]
    if spec.dtype not in (np.float32, np.float16):
        return f"input dtype {spec.dtype}, expected float32 (or float16)"
    if yolo_layout(spec) is None:
        return f"input shape {list(spec.shape)}, expected [1, 3, H, W] or [1, H, W, 3] with a static channel axis"
    out = sig.outputs[0]
    if (
        out.dtype not in (np.float32, np.float16)
        or len(out.shape) != 3
        or not all(map(_dim_is, out.shape[:2], (1, 56)))
    ):
        return f"output {out.dtype} {list(out.shape)}, expected float32 [1, 56, N]"
    if out.shape[1] is None and out.shape[2] == 56:
        return f"output {list(out.shape)} looks transposed ([1, N, 56]), expected float32 [1, 56, N]"
    return _half_dynamic(*(spec.shape[2:4] if yolo_layout(spec) == "nchw" else spec.shape[1:3]))


CONTRACTS: dict[str, Contract] = {
    MOVENET_MULTIPOSE: Contract(
        MOVENET_MULTIPOSE,
        "input int32 [1, H, W, 3] RGB 0-255 (H, W multiples of 32, often dynamic) -> output float32 [1, 6, 56]: "
        "per person 17 x (y, x, score) normalised, then ymin, xmin, ymax, xmax, box score",
        "Google MoveNet MultiPose Lightning (TF Hub / Kaggle Models 'movenet/multipose-lightning'), converted with "
        "tf2onnx: python -m tf2onnx.convert --saved-model DIR --output movenet_multipose.onnx",
        _multipose_mismatch,
    ),
    MOVENET_SINGLEPOSE: Contract(
        MOVENET_SINGLEPOSE,
        "input uint8 or int32 [1, 192, 192, 3] (Lightning) or [1, 256, 256, 3] (Thunder) RGB 0-255 -> output "
        "float32 [1, 1, 17, 3]: 17 x (y, x, score) normalised to the input; one person per image or crop",
        "Google MoveNet SinglePose Lightning/Thunder (TF Hub / Kaggle Models), converted with tf2onnx "
        "(--saved-model DIR, or --tflite FILE.tflite for the TFLite releases)",
        _singlepose_mismatch,
    ),
    YOLO_POSE: Contract(
        YOLO_POSE,
        "input float32 [1, 3, H, W] (NCHW) or [1, H, W, 3] (NHWC) RGB scaled to 0..1 -> output float32 "
        "[1, 56, N]: per candidate cx, cy, w, h, score, then 17 x (x, y, visibility), in input pixels or "
        "normalised to the input; no NMS inside",
        "Ultralytics YOLO pose models (yolov8n-pose.pt, yolo11n-pose.pt, ...): yolo export model=yolo11n-pose.pt "
        "format=onnx imgsz=640 (NMS not embedded)",
        _yolo_mismatch,
    ),
}


def supported_contracts_text() -> str:
    """Every supported contract with its signature and where such models usually come from (for errors/docs)."""
    lines = ["Supported pose-model contracts:"]
    for c in CONTRACTS.values():
        lines += [f"  - {c.name}: {c.signature}", f"      get it from: {c.source}"]
    lines.append("See docs/models.md.")
    return "\n".join(lines)


def detect_contract(signature: ModelSignature, contract: str | None = None, source: str = "model") -> str:
    """The contract that ``signature`` follows; ``contract`` names it explicitly (it must still fit).

    Raises PoseModelError when no contract fits, or when an explicit contract is unknown or does not fit.
    """
    if contract is not None:
        if contract not in CONTRACTS:
            raise PoseModelError(
                f"unknown pose-model contract {contract!r}; choose one of {', '.join(CONTRACTS)}.\n"
                + supported_contracts_text()
            )
        if reason := CONTRACTS[contract].mismatch(signature):
            raise PoseModelError(
                f"{source} does not fit contract {contract!r}: {reason}.\nIts signature: {signature}\n"
                + supported_contracts_text()
            )
        return contract
    reasons = {name: c.mismatch(signature) for name, c in CONTRACTS.items()}
    for name, reason in reasons.items():
        if reason is None:  # at most one fits: input dtypes and output ranks tell the contracts apart
            return name
    why = "\n".join(f"  - not {name}: {reason}" for name, reason in reasons.items())
    raise PoseModelError(
        f"{source} is not a supported pose model.\nIts signature: {signature}\n{why}\n" + supported_contracts_text()
    )
