"""Opening an ONNX model with onnxruntime, with session options chosen for a real-time perception loop.

Choices (see docs/models.md):
- ``intra_op_num_threads`` = physical cores this process may use (``sid.cpu.physical_cores``): one inference uses
  every core; hyper-threads add little to convolution throughput and contend with the rest of the pipeline.
  ``threads=`` overrides it (``sid detect --threads N``).
- Thread pools do not spin (``session.intra_op.allow_spinning`` and ``session.inter_op.allow_spinning`` = 0):
  onnxruntime's workers busy-wait between operators by default, which on a loaded or small machine steals the cores
  the other workers and the rest of the frame need (docs/parameters.md, "Pose sessions", has the measurements).
  ``spinning=True`` restores onnxruntime's default.
- ``inter_op_num_threads`` = 1 with sequential execution: pose graphs are a single chain of layers, there is no
  parallel branch worth a second thread pool.
- ``graph_optimization_level`` = ORT_ENABLE_ALL: constant folding, node fusions and layout optimisations; the
  one-off cost is paid once at load time.
- Providers (``providers="auto"``): TensorRT, then CUDA, when this onnxruntime build offers them (the
  ``onnxruntime-gpu`` package on a Jetson or desktop GPU), then OpenVINO (the ``onnxruntime-openvino`` package,
  ``pip install 'sid-social[openvino]'``; it gives the CPU provider's keypoints, usually in less ``session.run``
  time, but on a heavily loaded machine a whole ``sid detect`` ran slower with it: docs/parameters.md, "Pose
  sessions"), else CPU.
  ``"cpu"`` and ``"openvino"`` ask for one; asking for OpenVINO where it is not installed is an error. An explicit
  list of onnxruntime provider names is passed through as it is.
- Session log level = errors only; converter warnings about deprecated attributes are noise to a user. Those
  printed while the model loads go through onnxruntime's process-wide logger instead: it is held at errors only
  while the session is created and set back to warnings, its default, afterwards (``load_warnings=True`` leaves it
  alone, so they show). The ``sid`` commands call ``quiet_load_warnings()``: errors only for the whole process.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import onnxruntime as ort

from sid.cpu import physical_cores, usable_cpus
from sid.distribution import MissingDependencyError, install_hint
from sid.documents import special_file
from sid.errors import InputError
from sid.perception.pose.contracts import ModelSignature, PoseModelError, supported_contracts_text

__all__ = [
    "CPU_PROVIDER",
    "OPENVINO_MISSING",
    "OPENVINO_PROVIDER",
    "OnnxModel",
    "PREFERRED_PROVIDERS",
    "PROVIDER_CHOICES",
    "SPINNING_KEYS",
    "THREADS_PER_CPU",
    "check_threads",
    "default_providers",
    "quiet_load_warnings",
    "resolve_providers",
    "session_options",
    "ORT_WARNING",
    "ORT_ERROR",
]

CPU_PROVIDER = "CPUExecutionProvider"
OPENVINO_PROVIDER = "OpenVINOExecutionProvider"
PREFERRED_PROVIDERS: tuple[str, ...] = (
    "TensorrtExecutionProvider",
    "CUDAExecutionProvider",
    OPENVINO_PROVIDER,
    CPU_PROVIDER,
)
PROVIDER_CHOICES: tuple[str, ...] = ("auto", "cpu", "openvino")
SPINNING_KEYS: tuple[str, ...] = ("session.intra_op.allow_spinning", "session.inter_op.allow_spinning")
OPENVINO_MISSING = (
    "pose: the openvino provider is not available in this onnxruntime (available: {available}). Install it with "
    f"`{install_hint('openvino')}` (the onnxruntime-openvino package; it replaces the files of the plain "
    "onnxruntime package, so install it in its own environment or uninstall onnxruntime first), or use "
    "--provider auto or cpu"
)


def default_providers() -> list[str]:
    """The preferred execution providers this onnxruntime build offers, best first (CPU always last)."""
    available = set(ort.get_available_providers())
    return [p for p in PREFERRED_PROVIDERS if p in available] or [CPU_PROVIDER]


def resolve_providers(providers: str | Sequence[str] | None = None) -> list[str]:
    """The onnxruntime execution providers for a choice: None or ``"auto"`` (``default_providers()``), ``"cpu"``,
    ``"openvino"`` (then CPU for any operator OpenVINO does not take), or an explicit list of provider names.

    Raises ValueError for an unknown choice or an empty list, and ``sid.distribution.MissingDependencyError`` for
    ``"openvino"`` when this onnxruntime build does not offer it (the message says how to install it).
    """
    if providers is None:
        return default_providers()
    if isinstance(providers, str):
        choice = providers.strip().lower()
        if choice == "auto":
            return default_providers()
        if choice == "cpu":
            return [CPU_PROVIDER]
        if choice == "openvino":
            available = ort.get_available_providers()
            if OPENVINO_PROVIDER not in available:
                missing = OPENVINO_MISSING.format(available=", ".join(available)) + _overwritten_hint()
                raise MissingDependencyError(missing)
            return [OPENVINO_PROVIDER, CPU_PROVIDER]
        raise InputError(
            f"pose: unknown provider {providers!r}: expected one of {', '.join(PROVIDER_CHOICES)} "
            "or a list of onnxruntime provider names"
        )
    names = list(providers)
    if not names or not all(isinstance(name, str) and name for name in names):
        raise InputError(f"pose: providers must be a non-empty list of onnxruntime provider names, got {providers!r}")
    return names


ORT_WARNING, ORT_ERROR = 2, 3
"""onnxruntime's log severities: warnings (its process-wide logger's default) and errors."""
_process_quiet = False
"""Whether ``quiet_load_warnings`` made the process-wide logger report errors only."""


def quiet_load_warnings() -> None:
    """Make onnxruntime's process-wide logger report errors only: the warnings it prints while a model loads
    (YOLO11n-pose's exporter sets an attribute deprecated since opset 13, two lines per session) tell an operator
    nothing. Process-wide, like ``sid.cpu.keep_freed_memory``: call it from an entry point, never from library code."""
    global _process_quiet
    _process_quiet = True
    ort.set_default_logger_severity(ORT_ERROR)


@contextmanager
def _quiet_while_loading(load_warnings: bool) -> Iterator[None]:
    """onnxruntime's process-wide logger at errors only inside, then back at warnings (see the module docstring);
    nothing changes with ``load_warnings`` or after ``quiet_load_warnings``."""
    if load_warnings or _process_quiet:
        yield
        return
    ort.set_default_logger_severity(ORT_ERROR)
    try:
        yield
    finally:
        ort.set_default_logger_severity(ORT_WARNING)


THREADS_PER_CPU = 4
"""``check_threads`` refuses more intra-op threads than this per logical CPU the process may use: beyond one per CPU
they only queue behind each other, and a typo such as 100000 would start that many threads."""


def check_threads(threads: object) -> int | None:
    """``threads`` as an int in 1 .. ``THREADS_PER_CPU`` x the usable logical CPUs, or None (the default, physical
    cores); ValueError for anything else."""
    if threads is None:
        return None
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)):
        raise InputError(f"pose: threads must be a whole number >= 1, got {threads!r}")
    if threads < 1:
        raise InputError(f"pose: threads must be >= 1, got {threads}")
    cpus = len(usable_cpus())
    if threads > THREADS_PER_CPU * cpus:
        raise InputError(
            f"pose: threads must be at most {THREADS_PER_CPU * cpus} ({THREADS_PER_CPU} per logical CPU this process "
            f"may use, {cpus}), got {threads}"
        )
    return int(threads)


def session_options(threads: int | None = None, spinning: bool = False) -> ort.SessionOptions:
    """Session options for one pose model: ``threads`` intra-op threads (default: physical cores); thread pools
    spin-wait between operators only when ``spinning`` (onnxruntime's own default; see the module docstring)."""
    threads = check_threads(threads)
    options = ort.SessionOptions()
    options.intra_op_num_threads = threads or physical_cores()
    options.inter_op_num_threads = 1
    for key in SPINNING_KEYS:
        options.add_session_config_entry(key, "1" if spinning else "0")
    options.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    options.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_ALL
    options.log_severity_level = 3
    return options


class OnnxModel:
    """An onnxruntime session on one pose-model file, with its signature; ``run`` feeds the single input."""

    def __init__(
        self,
        path: str | Path,
        threads: int | None = None,
        providers: str | Sequence[str] | None = None,
        spinning: bool = False,
        load_warnings: bool = False,
    ):
        self.path = Path(path)
        self.threads = check_threads(threads) or physical_cores()
        self.spinning = spinning
        chosen = resolve_providers(providers)
        special = special_file(self.path)
        if special:
            raise PoseModelError(f"pose model {self.path}: {special}")
        if not self.path.is_file():
            hint = "" if self.path.suffix == ".onnx" else " (expected an .onnx file)"
            raise PoseModelError(f"pose model file not found: {self.path}{hint}\n" + supported_contracts_text())
        self.options = session_options(self.threads, spinning)
        self.provider_options = {name: _provider_options(name, self.threads) for name in chosen}
        try:
            with _quiet_while_loading(load_warnings):
                self.session = ort.InferenceSession(
                    str(self.path),
                    self.options,
                    providers=chosen,
                    provider_options=list(self.provider_options.values()),
                )
        except Exception as exc:  # onnxruntime raises several unrelated types for unreadable models
            raise PoseModelError(
                f"{self.path} is not an ONNX model onnxruntime can load ({type(exc).__name__}: {str(exc)[:300]}). "
                "TFLite, TF SavedModel or PyTorch files must be converted to ONNX first.\n" + supported_contracts_text()
            ) from exc
        asked_openvino = isinstance(providers, str) and providers.strip().lower() == "openvino"
        if asked_openvino and self.provider != OPENVINO_PROVIDER:  # onnxruntime fell back to CPU silently
            raise InputError(
                f"pose: the openvino provider failed to start on {self.path}; onnxruntime fell back to "
                f"{self.provider}; use --provider cpu (load_warnings=True shows onnxruntime's reason)"
            )
        self.signature = ModelSignature.from_session(self.session)
        self._input_name = self.session.get_inputs()[0].name if self.signature.inputs else ""
        self._output_name = self.session.get_outputs()[0].name if self.signature.outputs else ""

    @property
    def provider(self) -> str:
        """The execution provider that runs the model: the first the session uses (CPU when none other took it)."""
        return self.session.get_providers()[0]

    @property
    def providers(self) -> list[str]:
        """The execution providers the session actually uses, best first."""
        return self.session.get_providers()

    def run(self, tensor: np.ndarray) -> np.ndarray:
        """Run the model on its single input; returns the first output (as float32)."""
        (output,) = self.session.run([self._output_name], {self._input_name: tensor})
        return np.asarray(output, dtype=np.float32)


def _provider_options(provider: str, threads: int) -> dict[str, str]:
    """Options of one execution provider: OpenVINO runs on the CPU device with the session's thread count (its own
    thread pool does not read ``intra_op_num_threads``) and full float32 precision, like the CPU provider."""
    if provider == OPENVINO_PROVIDER:
        return {"device_type": "CPU", "num_of_threads": str(threads), "precision": "FP32"}
    return {}


def _overwritten_hint() -> str:
    """When the onnxruntime-openvino distribution is installed but the plain onnxruntime package's files replaced
    its module (both install ``onnxruntime``; the last one installed wins): how to put it back."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        installed = version("onnxruntime-openvino")
    except PackageNotFoundError:
        return ""
    return (
        f". onnxruntime-openvino {installed} is installed, but the plain onnxruntime package's files replaced it: "
        "pip uninstall -y onnxruntime && pip install --force-reinstall --no-deps onnxruntime-openvino"
    )
