"""Recognising the model contract from the ONNX signature, session options, and the errors for unusable files."""

from __future__ import annotations

import numpy as np
import onnxruntime as ort
import pytest
from onnx import TensorProto, helper

from sid.cpu import physical_cores
from sid.perception.pose import PoseEstimator, load_pose_estimator
from sid.perception.pose.contracts import (
    CONTRACTS,
    ModelSignature,
    PoseModelError,
    TensorSpec,
    detect_contract,
)
from sid.perception.pose.session import session_options
from tests.pose_models import build_multipose_model, build_singlepose_model, build_yolo_pose_model


def _signature(in_dtype, in_shape, out_shape, out_dtype=np.float32) -> ModelSignature:
    return ModelSignature(
        (TensorSpec("x", np.dtype(in_dtype), tuple(in_shape)),), (TensorSpec("y", np.dtype(out_dtype), out_shape),)
    )


@pytest.mark.parametrize(
    ("signature", "expected"),
    [
        (_signature(np.int32, (1, None, None, 3), (1, 6, 56)), "movenet_multipose"),
        (_signature(np.int32, (1, 256, 256, 3), (1, 6, 56)), "movenet_multipose"),
        (_signature(np.uint8, (1, 192, 192, 3), (1, 1, 17, 3)), "movenet_singlepose"),
        (_signature(np.int32, (1, 256, 256, 3), (1, 1, 17, 3)), "movenet_singlepose"),
        (_signature(np.float32, (1, 3, 640, 640), (1, 56, 8400)), "yolo_pose"),
        (_signature(np.float32, (1, 256, 256, 3), (1, 56, 1344)), "yolo_pose"),
        (_signature(np.float32, (1, 3, None, None), (1, 56, None)), "yolo_pose"),
    ],
)
def test_contract_is_read_from_the_signature(signature, expected):
    assert detect_contract(signature) == expected


def test_unknown_signature_lists_every_contract_with_its_source():
    signature = _signature(np.float32, (1, 3, 224, 224), (1, 1000))
    with pytest.raises(PoseModelError) as info:
        detect_contract(signature)
    text = str(info.value)
    for contract in CONTRACTS.values():
        assert contract.name in text
        assert contract.signature in text
    assert "tf2onnx" in text and "yolo export" in text
    assert "[1, 3, 224, 224]" in text  # says what the model has


def test_multipose_input_must_be_a_multiple_of_32():
    with pytest.raises(PoseModelError, match="multiples of 32"):
        detect_contract(_signature(np.int32, (1, 250, 256, 3), (1, 6, 56)), "movenet_multipose")


@pytest.mark.parametrize(
    ("in_dtype", "in_shape", "out_shape"),
    [
        (np.int32, (1, 256, None, 3), (1, 6, 56)),
        (np.uint8, (1, None, 192, 3), (1, 1, 17, 3)),
        (np.float32, (1, 3, 256, None), (1, 56, None)),
    ],
)
def test_half_dynamic_inputs_fit_no_contract(in_dtype, in_shape, out_shape):
    with pytest.raises(PoseModelError, match="one side fixed and the other dynamic"):
        detect_contract(_signature(in_dtype, in_shape, out_shape))


def test_explicit_contract_must_exist_and_fit():
    multipose = _signature(np.int32, (1, None, None, 3), (1, 6, 56))
    assert detect_contract(multipose, "movenet_multipose") == "movenet_multipose"
    with pytest.raises(PoseModelError, match="does not fit contract 'yolo_pose'"):
        detect_contract(multipose, "yolo_pose")
    with pytest.raises(PoseModelError, match="unknown pose-model contract 'openpose'"):
        detect_contract(multipose, "openpose")


@pytest.mark.parametrize("in_dtype", [np.uint8, np.int32, np.float32, np.float16])
@pytest.mark.parametrize("out_shape", [(None,) * 3, (None,) * 4, (1, 6, 56), (1, 1, 17, 3), (1, 56, None)])
def test_at_most_one_contract_fits_even_dynamic_signatures(in_dtype, out_shape):
    for in_shape in [(None,) * 4, (1, None, None, 3), (1, 3, None, None)]:
        signature = _signature(in_dtype, in_shape, out_shape)
        assert sum(c.mismatch(signature) is None for c in CONTRACTS.values()) <= 1


def test_missing_file_is_a_clear_error(tmp_path):
    with pytest.raises(PoseModelError, match="not found") as info:
        load_pose_estimator(tmp_path / "movenet.onnx")
    assert "movenet_multipose" in str(info.value)


def test_non_onnx_file_is_a_clear_error(tmp_path):
    path = tmp_path / "model.onnx"
    path.write_bytes(b"TFL3 this is a tflite flatbuffer, not onnx" * 10)
    with pytest.raises(PoseModelError, match="not an ONNX model") as info:
        load_pose_estimator(path)
    assert "converted to ONNX" in str(info.value)


def test_onnx_model_with_an_unknown_signature_is_a_clear_error(tmp_path):
    x = helper.make_tensor_value_info("x", TensorProto.FLOAT, [1, 10])
    y = helper.make_tensor_value_info("y", TensorProto.FLOAT, [1, 10])
    graph = helper.make_graph([helper.make_node("Relu", ["x"], ["y"])], "classifier", [x], [y])
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)])
    model.ir_version = 8
    path = tmp_path / "classifier.onnx"
    path.write_bytes(model.SerializeToString())
    with pytest.raises(PoseModelError, match="is not a supported pose model") as info:
        load_pose_estimator(path)
    assert "x: float32 [1, 10]" in str(info.value)


def test_tiny_models_are_recognised_and_explicit_options_are_checked(tmp_path):
    multipose = build_multipose_model(tmp_path / "multi.onnx")
    single = build_singlepose_model(tmp_path / "single.onnx")
    yolo = build_yolo_pose_model(tmp_path / "yolo.onnx", np.zeros((56, 10)))
    for path, name in [(multipose, "movenet_multipose"), (single, "movenet_singlepose"), (yolo, "yolo_pose")]:
        estimator = load_pose_estimator(path)
        assert estimator.contract == name and isinstance(estimator, PoseEstimator)
    with pytest.raises(PoseModelError, match="does not fit"):
        load_pose_estimator(single, contract="movenet_multipose")
    with pytest.raises(ValueError, match="iou_threshold applies to yolo_pose"):
        load_pose_estimator(multipose, iou_threshold=0.5)
    with pytest.raises(ValueError, match="fixed input"):
        load_pose_estimator(yolo, input_size=640)


def test_session_options_are_the_documented_ones():
    options = session_options()
    assert options.intra_op_num_threads == physical_cores() >= 1
    assert options.inter_op_num_threads == 1
    assert options.execution_mode == ort.ExecutionMode.ORT_SEQUENTIAL
    assert options.graph_optimization_level == ort.GraphOptimizationLevel.ORT_ENABLE_ALL
    assert session_options(threads=1).intra_op_num_threads == 1
    with pytest.raises(ValueError, match="threads"):
        session_options(threads=0)


def test_estimator_reports_threads_and_providers(tmp_path):
    estimator = load_pose_estimator(build_multipose_model(tmp_path / "m.onnx"), threads=1)
    assert estimator.model.threads == 1
    assert estimator.model.providers[-1] == "CPUExecutionProvider"
