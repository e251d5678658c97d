"""Static INT8 quantization of a pose model with onnxruntime's tools, calibrated on sid's own pre-processing.

``quantize_model(IN, OUT, images)`` writes an ONNX file with the same input and output (the same contract, so it
loads wherever the float model does) whose convolutions and matrix products run on 8-bit integers:

1. ``simplify_graph``: exact rewrites that leave every output bit for bit unchanged: pairs of multiplications by -1
   (TFLite converters write SiLU as ``x * sigmoid(x)`` through four of them), subtractions of zero and
   multiplications or divisions by one are removed (``simplify_model`` writes this float graph alone).
2. ``onnxruntime.quantization.quant_pre_process``: shape inference and onnxruntime's basic graph optimisations.
3. ``onnxruntime.quantization.quantize_static`` in QDQ format: activations uint8 with a per-tensor scale (min/max
   over the calibration images), weights int8 with a per-output-channel scale: the combination onnxruntime runs on
   integer dot-product instructions (VNNI on x86, SDOT on ARMv8.2+); int8 activations fall back to slower kernels
   on x86. The last ``FLOAT_LAYERS`` weighted layers of every path to the outputs and the decoding after them
   (keypoint offsets, anchors, scores, the output concatenation) stay float (``decoding_nodes``): 8-bit steps there
   move keypoints by pixels, and the facings lifted from them by degrees. The exception is a branch that reaches
   only the candidates' boxes (``BOX_OUTPUTS``: YOLO's box regression, which serves non-maximum suppression and
   the box fields, not the keypoints): it is quantized whole (``box_branch_nodes``). See docs/models.md for what
   each choice costs.

Calibration tensors are made by the model's own estimator (``preprocess`` of ``sid.perception.pose``: letterbox,
padding value, dtype, layout), from whole RGB images, exactly as ``sid detect`` feeds the model.

Needs the ``onnx`` package (``pip install 'sid-social[quantize]'``); onnxruntime's quantization tools import it.
"""

from __future__ import annotations

import os
import tempfile
import time
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from sid.distribution import MissingDependencyError, install_hint
from sid.errors import InputError
from sid.perception.pose.contracts import YOLO_POSE, PoseModelError

if TYPE_CHECKING:
    import onnx

__all__ = [
    "BOX_OUTPUTS",
    "FLOAT_LAYERS",
    "ONNX_MISSING",
    "QUANTIZED_OPS",
    "QuantizeReport",
    "WEIGHTED_OPS",
    "box_branch_nodes",
    "check_paths",
    "decoding_nodes",
    "is_quantized",
    "quantize_model",
    "quantized_nodes",
    "simplify_graph",
    "simplify_model",
]

WEIGHTED_OPS = ("Conv", "ConvTranspose", "MatMul", "Gemm")
"""Operators whose int8 kernels make the speed-up; the graph after the last of them is the decoding, kept float."""
QUANTIZED_OPS = ("QuantizeLinear", "DequantizeLinear", "QLinearConv", "QLinearMatMul", "ConvInteger", "MatMulInteger")
"""Operators of a quantized graph: a model holding them is quantized already (onnxruntime's tools loop for ever on
one, or write a model that does not load)."""
FLOAT_LAYERS = 4
"""``quantize_model``'s default: the last 4 weighted layers on every path to the outputs stay float, with the decoding
after them (docs/models.md has the measurements that chose it)."""
BOX_OUTPUTS: dict[str, tuple[int, slice]] = {YOLO_POSE: (1, slice(0, 4))}
"""Where a contract's output holds the candidates' boxes, as (axis, index range): rows 0-3 (cx, cy, w, h) of YOLO's
[1, 56, N]. The layers that reach nothing else are quantized whole by ``quantize_model``."""
ONNX_MISSING = f"editing ONNX graphs needs the onnx package: {install_hint('quantize')} (or pip install onnx)"


@dataclass(frozen=True)
class QuantizeReport:
    """What ``quantize_model`` did: the contract both files follow, how many calibration images it used, how many
    nodes the exact simplification removed, how many nodes it quantized and kept float, how many of the quantized
    ones are the box branch (``box_branch_nodes``), and its duration (s)."""

    source: Path
    output: Path
    contract: str
    calibration_images: int
    removed_nodes: int
    quantized_nodes: int
    float_nodes: int
    box_branch_nodes: int
    seconds: float


def _onnx() -> Any:
    try:
        import onnx
    except ImportError:
        raise MissingDependencyError(ONNX_MISSING) from None
    return onnx


def simplify_graph(model: onnx.ModelProto) -> int:
    """Remove, in place, nodes of ``model`` that leave their input unchanged bit for bit: ``Mul`` by -1 followed
    only by another ``Mul`` by -1, ``Sub`` of a zero constant, ``Mul`` or ``Div`` by a one constant, each only where
    shape inference shows that the constant does not broadcast the input to another shape (``Add`` of zero is
    left: it turns -0 into +0). Returns how many nodes went."""
    from onnx import numpy_helper, shape_inference

    graph = model.graph
    constants = {init.name: numpy_helper.to_array(init) for init in graph.initializer}
    shapes: dict[str, tuple[int | None, ...]] = {}
    for info in (*shape_inference.infer_shapes(model).graph.value_info, *graph.input):
        if info.type.HasField("tensor_type") and info.type.tensor_type.HasField("shape"):
            dims = info.type.tensor_type.shape.dim
            shapes[info.name] = tuple(d.dim_value if d.HasField("dim_value") else None for d in dims)
    nodes = list(graph.node)  # one Python object per node for the whole pass: their ids identify them
    consumers = _consumers(nodes)
    outputs = {output.name for output in graph.output}

    def scalar_operand(node: Any, value: float, ops: tuple[str, ...], commutes: bool) -> str | None:
        """The other input of ``node`` when it is one of ``ops`` with a constant of ``value`` everywhere, else None."""
        if node.op_type not in ops or len(node.input) != 2 or node.output[0] in outputs:
            return None
        first, second = node.input
        for constant, other in ((second, first), (first, second)) if commutes else ((second, first),):
            array = constants.get(constant)
            if array is not None and array.size >= 1 and np.all(array == value) and _keeps_shape(shapes, other, array):
                return other
        return None

    replaced: dict[str, str] = {}  # output name -> the tensor it equals
    removed: set[int] = set()
    for node in nodes:
        if id(node) in removed:
            continue
        negated = scalar_operand(node, -1.0, ("Mul",), commutes=True)
        if negated is not None:
            following = consumers.get(node.output[0], [])
            if len(following) == 1 and scalar_operand(following[0], -1.0, ("Mul",), commutes=True) is not None:
                removed |= {id(node), id(following[0])}
                replaced[following[0].output[0]] = negated
            continue
        same = (
            scalar_operand(node, 0.0, ("Sub",), False)
            or scalar_operand(node, 1.0, ("Mul",), commutes=True)
            or scalar_operand(node, 1.0, ("Div",), False)
        )
        if same is not None:
            removed.add(id(node))
            replaced[node.output[0]] = same

    def resolve(name: str) -> str:
        while name in replaced:
            name = replaced[name]
        return name

    kept = [node for node in nodes if id(node) not in removed]
    for node in kept:
        for k, name in enumerate(node.input):
            node.input[k] = resolve(name)
    del graph.node[:]
    graph.node.extend(kept)
    used = {name for node in graph.node for name in node.input}
    live = [init for init in graph.initializer if init.name in used]
    del graph.initializer[:]
    graph.initializer.extend(live)
    return len(removed)


def _consumers(nodes: Iterable[Any]) -> dict[str, list[Any]]:
    """Tensor name -> the nodes that read it, in the graph's order."""
    consumers: dict[str, list[Any]] = {}
    for node in nodes:
        for name in node.input:
            consumers.setdefault(name, []).append(node)
    return consumers


def _keeps_shape(shapes: dict[str, tuple[int | None, ...]], name: str, constant: np.ndarray) -> bool:
    """Whether broadcasting ``constant`` against the tensor ``name`` leaves that tensor's (inferred) shape as it is."""
    shape = shapes.get(name)
    if shape is None or constant.ndim > len(shape):
        return False
    trailing = shape[len(shape) - constant.ndim :]
    return all(c == 1 or c == d for c, d in zip(constant.shape, trailing, strict=True))


def decoding_nodes(model: onnx.ModelProto, layers: int = FLOAT_LAYERS) -> list[str]:
    """Names of the nodes followed by fewer than ``layers`` weighted operators (``WEIGHTED_OPS``) on every path to
    the outputs, in the graph's order: with ``layers`` = K, the last K weighted layers of each path and everything
    after them (the decoding), without the activations that feed the first of those layers."""
    nodes = list(model.graph.node)
    consumers = _consumers(nodes)
    after: dict[int, int] = {}  # node -> most weighted operators on a path from its output to the graph's outputs
    for node in reversed(nodes):  # ONNX graphs are topologically sorted: consumers come after producers
        following = [c for output in node.output for c in consumers.get(output, [])]
        after[id(node)] = max((after[id(c)] + (c.op_type in WEIGHTED_OPS) for c in following), default=0)
    return [node.name for node in nodes if after[id(node)] < layers]


def box_branch_nodes(
    model: onnx.ModelProto, region: Sequence[str], tensor: np.ndarray, box: tuple[int, slice]
) -> set[str]:
    """The nodes among ``region`` (node names) that reach only the box part of the model's output (``box``: axis and
    index range): the weighted nodes whose weights, changed, change nothing else of the output for ``tensor`` (the
    float model run once per node; an output element counts as changed beyond 1e-6 relative), and the nodes all of
    whose consumers are such nodes. Weights that are not initializers, or that another node shares, count as
    reaching everything. Only the region's weighted nodes are tried, so this costs a run per weighted node in it."""
    import onnxruntime as ort
    from onnx import numpy_helper

    graph = model.graph
    inits = {init.name: k for k, init in enumerate(graph.initializer)}
    consumers = _consumers(graph.node)
    options = ort.SessionOptions()
    options.intra_op_num_threads = 1

    def run(candidate: onnx.ModelProto) -> np.ndarray:
        session = ort.InferenceSession(candidate.SerializeToString(), options, providers=["CPUExecutionProvider"])
        return np.asarray(session.run(None, {session.get_inputs()[0].name: tensor})[0], dtype=np.float64)

    reference = run(model)
    axis, rows = box
    others = np.ones(reference.shape[axis], dtype=bool)
    others[rows] = False
    inside = set(region)
    reaching_boxes: set[str] = set()
    for node in graph.node:
        if node.name not in inside or node.op_type not in WEIGHTED_OPS or len(node.input) < 2:
            continue
        weights = node.input[1]
        if weights not in inits or len(consumers[weights]) != 1:
            continue
        changed = type(model)()
        changed.CopyFrom(model)
        array = numpy_helper.to_array(graph.initializer[inits[weights]])
        changed.graph.initializer[inits[weights]].CopyFrom(numpy_helper.from_array(array * 0.5 + 0.1, weights))
        moved = np.abs(run(changed) - reference) > 1e-6 * (1.0 + np.abs(reference))
        moved_rows = moved.any(axis=tuple(a for a in range(moved.ndim) if a != axis))
        if moved_rows.any() and not moved_rows[others].any():
            reaching_boxes.add(node.name)
    outputs = {output.name for output in graph.output}
    for node in reversed(graph.node):  # consumers after producers: a node's consumers are decided before it
        if node.name not in inside or node.name in reaching_boxes or node.op_type in WEIGHTED_OPS:
            continue
        following = [c for name in node.output for c in consumers.get(name, [])]
        feeds_output = any(name in outputs for name in node.output)
        if following and not feeds_output and all(c.name in reaching_boxes for c in following):
            reaching_boxes.add(node.name)
    return reaching_boxes


def simplify_model(source: str | Path, output: str | Path) -> int:
    """Write ``simplify_graph`` of the model at ``source`` to ``output`` (float, outputs unchanged); returns how
    many nodes it removed. Raises PoseModelError when ``source`` is not a pose model sid can load."""
    from sid.perception.pose import load_pose_estimator

    source, output = check_paths(source, output)
    contract = load_pose_estimator(source, threads=1).contract
    onnx = _onnx()
    model = onnx.load(str(source))
    removed = simplify_graph(model)
    onnx.save(model, str(output))
    _check_contract(output, contract)
    return removed


def quantize_model(
    source: str | Path,
    output: str | Path,
    images: Iterable[np.ndarray],
    *,
    per_channel: bool = True,
    float_layers: int = FLOAT_LAYERS,
    float_boxes: bool = False,
    max_images: int | None = None,
) -> QuantizeReport:
    """Quantize the pose model at ``source`` to INT8 (module docstring) and write it to ``output``.

    images: RGB uint8 (H, W, 3) calibration images, e.g. the colour images of a sid source; each goes through the
    model's own pre-processing. max_images: use at most this many. per_channel: weights get one scale per output
    channel (else one per tensor). float_layers: leave ``decoding_nodes`` with that many layers float (0: none).
    float_boxes: keep the branch that reaches only the boxes (``box_branch_nodes``) float too, as the other paths.

    The model is written next to ``output`` under a temporary name and renamed when it loads with the source's
    contract: a failed run leaves no file.

    Raises PoseModelError (source missing, not a pose model or quantized already, nothing to quantize, the written
    model not loading with the same contract), ValueError (no calibration image, output = source),
    MissingDependencyError (onnx not installed).
    """
    onnx = _onnx()  # before onnxruntime.quantization, which imports onnx itself
    from onnxruntime.quantization import CalibrationMethod, QuantFormat, QuantType, quantize_static
    from onnxruntime.quantization.shape_inference import quant_pre_process

    from sid.perception.pose import load_pose_estimator

    if isinstance(float_layers, bool) or not isinstance(float_layers, int) or float_layers < 0:
        raise InputError(f"float_layers must be a whole number >= 0, got {float_layers!r}")
    started = time.perf_counter()
    source, output = check_paths(source, output)
    estimator = load_pose_estimator(source, threads=1)
    input_name = estimator.model.signature.inputs[0].name
    tensors = [estimator.preprocess(image)[0] for image in _first(images, max_images)]
    if not tensors:
        raise InputError("no calibration image: the calibration source gave no frames")
    model = onnx.load(str(source))
    quantized = quantized_nodes(model)
    if quantized:
        raise PoseModelError(f"{source} is quantized already ({quantized} quantized nodes); quantize the float model")
    removed = simplify_graph(model)
    weighted = sum(node.op_type in WEIGHTED_OPS for node in model.graph.node)
    if weighted == 0:
        raise PoseModelError(f"{source}: no {', '.join(WEIGHTED_OPS)} node to quantize")
    written = output.with_name(f".{output.name}.sid-quantize-{os.getpid()}.onnx")  # renamed once it loads
    try:
        with tempfile.TemporaryDirectory(prefix="sid-quantize-") as work:
            simplified, prepared = Path(work) / "simplified.onnx", Path(work) / "prepared.onnx"
            onnx.save(model, str(simplified))
            quant_pre_process(str(simplified), str(prepared), skip_symbolic_shape=True)
            prepared_model = onnx.load(str(prepared))
            keep_float = decoding_nodes(prepared_model, float_layers) if float_layers else []
            box = BOX_OUTPUTS.get(estimator.contract)
            boxes = (
                box_branch_nodes(prepared_model, keep_float, tensors[0], box)
                if keep_float and box and not float_boxes
                else set()
            )
            keep_float = [name for name in keep_float if name not in boxes]
            quantize_static(
                str(prepared),
                str(written),
                _CalibrationImages(input_name, tensors),
                quant_format=QuantFormat.QDQ,
                per_channel=per_channel,
                activation_type=QuantType.QUInt8,
                weight_type=QuantType.QInt8,
                calibrate_method=CalibrationMethod.MinMax,
                nodes_to_exclude=keep_float,
            )
            nodes = len(prepared_model.graph.node)
        made = sum(node.op_type == "QuantizeLinear" for node in onnx.load(str(written)).graph.node)
        if not made:
            raise PoseModelError(
                f"{source}: nothing was quantized (float_layers {float_layers} keeps every weighted layer float); "
                "lower --float-layers"
            )
        _check_contract(written, estimator.contract)
        written.replace(output)
    finally:
        written.unlink(missing_ok=True)
    return QuantizeReport(
        source,
        output,
        estimator.contract,
        len(tensors),
        removed,
        nodes - len(keep_float),
        len(keep_float),
        len(boxes),
        time.perf_counter() - started,
    )


class _CalibrationImages:
    """onnxruntime's ``CalibrationDataReader`` protocol (``get_next``, ``rewind``) over prepared input tensors."""

    def __init__(self, input_name: str, tensors: Sequence[np.ndarray]) -> None:
        self.input_name = input_name
        self.tensors = tensors
        self._next = iter(tensors)

    def get_next(self) -> dict[str, np.ndarray] | None:
        tensor = next(self._next, None)
        return None if tensor is None else {self.input_name: tensor}

    def rewind(self) -> None:
        self._next = iter(self.tensors)


def _first(images: Iterable[np.ndarray], limit: int | None) -> Iterator[np.ndarray]:
    for count, image in enumerate(images):
        if limit is not None and count >= limit:
            return
        yield image


def quantized_nodes(model: Any) -> int:
    """How many nodes of the ONNX ``model`` (an ``onnx.ModelProto``) are ``QUANTIZED_OPS``: 0 for a float model."""
    return sum(node.op_type in QUANTIZED_OPS for node in model.graph.node)


def is_quantized(path: str | Path) -> bool:
    """Whether the ONNX model at ``path`` is quantized already (``quantized_nodes``); needs the onnx package."""
    return quantized_nodes(_onnx().load(str(path), load_external_data=False)) > 0


def check_paths(source: str | Path, output: str | Path) -> tuple[Path, Path]:
    """``source`` and ``output`` as Paths; ValueError when the output is the source, a folder, or in a folder that
    does not exist (checked before any work)."""
    source, output = Path(source), Path(output)
    if source.exists() and output.exists() and os.path.samefile(source, output):  # a link to it too, hard or soft
        raise InputError(f"the output {output} is the input model; write to another file")
    if output.is_dir():
        raise InputError(f"the output {output} is a folder; name a .onnx file")
    if not output.parent.is_dir():
        raise InputError(f"cannot write {output}: the folder {output.parent} does not exist")
    return source, output


def _check_contract(path: Path, contract: str) -> None:
    """The written model must load and follow the source's contract (so it works wherever the source does)."""
    from sid.perception.pose import load_pose_estimator

    written = load_pose_estimator(path, threads=1).contract
    if written != contract:
        raise PoseModelError(f"{path}: the written model follows {written}, not the source's {contract}")
