"""Opening an ONNX model with onnxruntime, with session options chosen for a real-time perception loop.

Choices (see docs/models.md):
- ``intra_op_num_threads`` = physical cores this process may use (``sid.cpu.physical_cores``): one inference uses
  every core; hyper-threads add little to convolution throughput and contend with the rest of the pipeline.
- ``inter_op_num_threads`` = 1 with sequential execution: pose graphs are a single chain of layers, there is no
  parallel branch worth a second thread pool.
- ``graph_optimization_level`` = ORT_ENABLE_ALL: constant folding, node fusions and layout optimisations; the
  one-off cost is paid once at load time.
- Providers: TensorRT, then CUDA, when this onnxruntime build offers them (the ``onnxruntime-gpu`` package on a
  Jetson or desktop GPU), else CPU. An explicit list overrides this.
- Session log level = errors only; converter warnings about deprecated attributes are noise to a user.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import onnxruntime as ort

from sid.cpu import physical_cores
from sid.perception.pose.contracts import ModelSignature, PoseModelError, supported_contracts_text

PREFERRED_PROVIDERS: tuple[str, ...] = ("TensorrtExecutionProvider", "CUDAExecutionProvider", "CPUExecutionProvider")


def default_providers() -> list[str]:
    """The preferred execution providers this onnxruntime build offers, best first (CPU always last)."""
    available = set(ort.get_available_providers())
    return [p for p in PREFERRED_PROVIDERS if p in available] or ["CPUExecutionProvider"]


def session_options(threads: int | None = None) -> ort.SessionOptions:
    """Session options for one pose model: ``threads`` intra-op threads (default: physical cores)."""
    if threads is not None and threads < 1:
        raise ValueError(f"pose: threads must be >= 1, got {threads}")
    options = ort.SessionOptions()
    options.intra_op_num_threads = threads or physical_cores()
    options.inter_op_num_threads = 1
    options.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    options.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_ALL
    options.log_severity_level = 3
    return options


class OnnxModel:
    """An onnxruntime session on one pose-model file, with its signature; ``run`` feeds the single input."""

    def __init__(self, path: str | Path, threads: int | None = None, providers: Sequence[str] | None = None):
        self.path = Path(path)
        if not self.path.is_file():
            hint = "" if self.path.suffix == ".onnx" else " (expected an .onnx file)"
            raise PoseModelError(f"pose model file not found: {self.path}{hint}\n" + supported_contracts_text())
        self.threads = threads or physical_cores()
        try:
            self.session = ort.InferenceSession(
                str(self.path), session_options(self.threads), providers=list(providers or default_providers())
            )
        except Exception as exc:  # onnxruntime raises several unrelated types for unreadable models
            raise PoseModelError(
                f"{self.path} is not an ONNX model onnxruntime can load ({type(exc).__name__}: {str(exc)[:300]}). "
                "TFLite, TF SavedModel or PyTorch files must be converted to ONNX first.\n" + supported_contracts_text()
            ) from exc
        self.signature = ModelSignature.from_session(self.session)
        self._input_name = self.session.get_inputs()[0].name if self.signature.inputs else ""
        self._output_name = self.session.get_outputs()[0].name if self.signature.outputs else ""

    @property
    def providers(self) -> list[str]:
        """The execution providers the session actually uses, best first."""
        return self.session.get_providers()

    def run(self, tensor: np.ndarray) -> np.ndarray:
        """Run the model on its single input; returns the first output (as float32)."""
        (output,) = self.session.run([self._output_name], {self._input_name: tensor})
        return np.asarray(output, dtype=np.float32)
