"""Tiny ONNX models with the signatures of the supported contracts, for tests without real weights.

Each model answers a crafted output. A "marker" model also looks at its input: it finds the brightest pixel of the
red channel and adds that pixel centre's normalised (y, x) to the crafted keypoints (and boxes), so a test can put
a red dot in an image and check that the keypoint comes back on the dot in image pixels (this checks RGB order,
dtype, letterboxing and the inverse map together).

Needs the ``onnx`` package (in sid's ``test`` extra, not a runtime dependency).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

OPSET = 17
IR_VERSION = 8  # loadable by every onnxruntime sid supports (>= 1.17)


def _build(path: str | Path, nodes: list, x_info, y_info, initializers: dict[str, np.ndarray]) -> Path:
    inits = [numpy_helper.from_array(np.asarray(v), name=k) for k, v in initializers.items()]
    graph = helper.make_graph(nodes, "sid_test_pose_model", [x_info], [y_info], initializer=inits)
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", OPSET)], producer_name="sid tests")
    model.ir_version = IR_VERSION
    onnx.checker.check_model(model)
    path = Path(path)
    onnx.save(model, str(path))
    return path


def _marker_nodes(channels_last: bool = True) -> tuple[list, dict[str, np.ndarray]]:
    """Nodes computing ``marker_y``, ``marker_x`` ([1] float): normalised centre of the brightest red pixel of X."""
    h_axis, w_axis, c_axis = (1, 2, 3) if channels_last else (2, 3, 1)
    return [
        helper.make_node("Slice", ["X", "c0", "c1", "c_axis"], ["red"]),
        helper.make_node("Cast", ["red"], ["red_f"], to=1),
        helper.make_node("Reshape", ["red_f", "flat"], ["red_flat"]),
        helper.make_node("ArgMax", ["red_flat"], ["index"], axis=0, keepdims=1),
        helper.make_node("Shape", ["X"], ["shape"]),
        helper.make_node("Gather", ["shape", "h_axis"], ["H"]),
        helper.make_node("Gather", ["shape", "w_axis"], ["W"]),
        helper.make_node("Div", ["index", "W"], ["row"]),
        helper.make_node("Mod", ["index", "W"], ["col"]),
        *[helper.make_node("Cast", [a], [a + "_f"], to=1) for a in ("row", "col", "H", "W")],
        helper.make_node("Add", ["row_f", "half"], ["row_c"]),
        helper.make_node("Add", ["col_f", "half"], ["col_c"]),
        helper.make_node("Div", ["row_c", "H_f"], ["marker_y"]),
        helper.make_node("Div", ["col_c", "W_f"], ["marker_x"]),
    ], {
        "c0": np.array([0], np.int64),
        "c1": np.array([1], np.int64),
        "c_axis": np.array([c_axis], np.int64),
        "flat": np.array([-1], np.int64),
        "h_axis": np.array([h_axis], np.int64),
        "w_axis": np.array([w_axis], np.int64),
        "half": np.array([0.5], np.float32),
    }


def _crafted_output(base: np.ndarray, y_mask: np.ndarray, x_mask: np.ndarray, marker: bool, channels_last=True):
    """Nodes and constants for Y = base + marker_y * y_mask + marker_x * x_mask (masks zero without a marker)."""
    nodes, consts = _marker_nodes(channels_last)
    scale = np.float32(1.0 if marker else 0.0)
    consts |= {"base": base.astype(np.float32), "y_mask": scale * y_mask, "x_mask": scale * x_mask}
    nodes += [
        helper.make_node("Mul", ["marker_y", "y_mask"], ["dy"]),
        helper.make_node("Mul", ["marker_x", "x_mask"], ["dx"]),
        helper.make_node("Add", ["base", "dy"], ["base_dy"]),
        helper.make_node("Add", ["base_dy", "dx"], ["Y"]),
    ]
    return nodes, consts


def build_multipose_model(
    path: str | Path,
    people: np.ndarray | None = None,
    input_hw: tuple[int | None, int | None] = (None, None),
    marker: bool = False,
) -> Path:
    """MoveNet MultiPose signature: int32 [1, H, W, 3] -> float32 [1, 6, 56] equal to ``people`` (6, 56).

    With ``marker`` the marker's normalised (y, x) is added to person 0's keypoint and box (y, x) entries.
    ``input_hw`` None entries are dynamic dimensions.
    """
    base = np.zeros((1, 6, 56), np.float32) if people is None else np.asarray(people, np.float32).reshape(1, 6, 56)
    y_mask, x_mask = np.zeros((1, 6, 56), np.float32), np.zeros((1, 6, 56), np.float32)
    y_mask[0, 0, [*range(0, 51, 3), 51, 53]] = 1.0
    x_mask[0, 0, [*range(1, 51, 3), 52, 54]] = 1.0
    nodes, consts = _crafted_output(base, y_mask, x_mask, marker)
    x_info = helper.make_tensor_value_info(
        "X", TensorProto.INT32, [1, input_hw[0] or "height", input_hw[1] or "width", 3]
    )
    y_info = helper.make_tensor_value_info("Y", TensorProto.FLOAT, [1, 6, 56])
    return _build(path, nodes, x_info, y_info, consts)


def build_singlepose_model(
    path: str | Path,
    keypoints: np.ndarray | None = None,
    size: int = 192,
    dtype: type = np.uint8,
    marker: bool = False,
) -> Path:
    """MoveNet SinglePose signature: uint8/int32 [1, size, size, 3] -> float32 [1, 1, 17, 3] equal to
    ``keypoints`` (17, 3) as (y, x, score); with ``marker`` the marker's (y, x) is added to every keypoint."""
    base = np.zeros((1, 1, 17, 3), np.float32) if keypoints is None else np.asarray(keypoints).reshape(1, 1, 17, 3)
    y_mask, x_mask = np.zeros((1, 1, 17, 3), np.float32), np.zeros((1, 1, 17, 3), np.float32)
    y_mask[..., 0], x_mask[..., 1] = 1.0, 1.0
    nodes, consts = _crafted_output(base, y_mask, x_mask, marker)
    elem = {np.dtype(np.uint8): TensorProto.UINT8, np.dtype(np.int32): TensorProto.INT32}[np.dtype(dtype)]
    x_info = helper.make_tensor_value_info("X", elem, [1, size, size, 3])
    y_info = helper.make_tensor_value_info("Y", TensorProto.FLOAT, [1, 1, 17, 3])
    return _build(path, nodes, x_info, y_info, consts)


def build_yolo_pose_model(
    path: str | Path,
    candidates: np.ndarray,
    input_hw: Sequence[int] = (256, 256),
    layout: str = "nhwc",
) -> Path:
    """YOLO-pose signature: float32 [1, H, W, 3] (``layout="nhwc"``) or [1, 3, H, W] -> float32 [1, 56, N]
    equal to ``candidates`` (56, N): cx, cy, w, h, score, 17 x (x, y, visibility), in whatever units you give."""
    base = np.asarray(candidates, np.float32).reshape(1, 56, -1)
    zeros = np.zeros_like(base)
    nodes, consts = _crafted_output(base, zeros, zeros, marker=False, channels_last=layout == "nhwc")
    h, w = input_hw
    shape = [1, h, w, 3] if layout == "nhwc" else [1, 3, h, w]
    x_info = helper.make_tensor_value_info("X", TensorProto.FLOAT, shape)
    y_info = helper.make_tensor_value_info("Y", TensorProto.FLOAT, list(base.shape))
    return _build(path, nodes, x_info, y_info, consts)


def build_model_with_output(
    path: str | Path, output: np.ndarray, declared: Sequence[int | str], input_shape: Sequence[int | str]
) -> Path:
    """Float32 input of ``input_shape`` -> float32 ``output``, declared as ``declared`` (str entries dynamic).

    The output goes through a Reshape whose target depends on the input's values, so onnxruntime cannot infer
    its shape and reports the declared one, as it does for a real export with dynamic axes.
    """
    nodes, consts = _marker_nodes(channels_last=input_shape[-1] == 3)
    consts |= {"base": np.asarray(output, np.float32).ravel(), "dims": np.array(output.shape, np.int64)}
    nodes += [
        helper.make_node("Mul", ["index", "c0"], ["zero"]),  # 0, but only known when the model runs
        helper.make_node("Add", ["dims", "zero"], ["target"]),
        helper.make_node("Reshape", ["base", "target"], ["Y"]),
    ]
    x_info = helper.make_tensor_value_info("X", TensorProto.FLOAT, list(input_shape))
    y_info = helper.make_tensor_value_info("Y", TensorProto.FLOAT, list(declared))
    return _build(path, nodes, x_info, y_info, consts)


def yolo_candidate(box_xywh: Sequence[float], score: float, keypoints_xy: np.ndarray, visibility: float = 0.9):
    """One (56,) YOLO candidate column from a box (cx, cy, w, h), a score and (17, 2) keypoints (x, y)."""
    kpts = np.concatenate([np.asarray(keypoints_xy, float).reshape(17, 2), np.full((17, 1), visibility)], axis=1)
    return np.concatenate([np.asarray(box_xywh, float), [score], kpts.ravel()]).astype(np.float32)
