"""Session settings of the pose models: threads, spinning and execution providers reach onnxruntime; the OpenVINO
provider gives the CPU provider's keypoints (run only where onnxruntime-openvino is installed)."""

from __future__ import annotations

import re

import cv2
import numpy as np
import onnxruntime as ort
import pytest

from sid.cpu import physical_cores
from sid.distribution import MissingDependencyError, install_hint
from sid.perception.pose import load_pose_estimator
from sid.perception.pose.session import (
    CPU_PROVIDER,
    OPENVINO_PROVIDER,
    SPINNING_KEYS,
    default_providers,
    resolve_providers,
    session_options,
)
from tests.conftest import REPO_ROOT, shared_path
from tests.pose_models import IR_VERSION, build_multipose_model

HAS_OPENVINO = OPENVINO_PROVIDER in ort.get_available_providers()
needs_openvino = pytest.mark.skipif(
    not HAS_OPENVINO,
    reason="onnxruntime-openvino is not installed (pip install 'sid-social[openvino]' in its own environment)",
)


def _spinning(options: ort.SessionOptions) -> list[str]:
    return [options.get_session_config_entry(key) for key in SPINNING_KEYS]


def test_thread_pools_do_not_spin_by_default():
    assert _spinning(session_options()) == ["0", "0"]
    assert _spinning(session_options(spinning=True)) == ["1", "1"]


def test_threads_and_spinning_reach_the_session(tmp_path):
    path = build_multipose_model(tmp_path / "m.onnx")
    estimator = load_pose_estimator(path, threads=1)
    assert estimator.model.threads == 1
    assert estimator.model.options.intra_op_num_threads == 1
    assert _spinning(estimator.model.options) == ["0", "0"]
    # the session itself was built from these options: its own copy reads back the same values
    assert _spinning(estimator.model.session.get_session_options()) == ["0", "0"]
    assert estimator.model.session.get_session_options().intra_op_num_threads == 1
    default = load_pose_estimator(path)
    assert default.model.options.intra_op_num_threads == default.model.threads == physical_cores()
    spinning = load_pose_estimator(path, threads=2, spinning=True)
    assert _spinning(spinning.model.session.get_session_options()) == ["1", "1"]
    assert spinning.model.session.get_session_options().intra_op_num_threads == 2


@pytest.mark.parametrize("threads", [0, -2, 1.5, "2", True, 100_000])
def test_bad_thread_counts_are_refused(tmp_path, threads):
    with pytest.raises(ValueError, match="threads must be"):
        session_options(threads=threads)
    with pytest.raises(ValueError, match="threads must be"):
        load_pose_estimator(build_multipose_model(tmp_path / "m.onnx"), threads=threads)


def test_provider_choices():
    assert resolve_providers("cpu") == [CPU_PROVIDER]
    assert resolve_providers(None) == resolve_providers("auto") == resolve_providers("AUTO") == default_providers()
    assert default_providers()[-1] == CPU_PROVIDER
    assert (OPENVINO_PROVIDER in default_providers()) == HAS_OPENVINO
    assert resolve_providers(["CPUExecutionProvider"]) == [CPU_PROVIDER]
    with pytest.raises(ValueError, match="unknown provider 'gpu': expected one of auto, cpu, openvino"):
        resolve_providers("gpu")
    with pytest.raises(ValueError, match="non-empty list"):
        resolve_providers([])


def test_cpu_provider_reaches_the_session(tmp_path):
    estimator = load_pose_estimator(build_multipose_model(tmp_path / "m.onnx"), providers="cpu")
    assert estimator.model.providers == [CPU_PROVIDER] and estimator.model.provider == CPU_PROVIDER


def test_unknown_provider_is_refused_before_loading(tmp_path):
    with pytest.raises(ValueError, match="unknown provider 'cuda'"):
        load_pose_estimator(build_multipose_model(tmp_path / "m.onnx"), providers="cuda")


@pytest.mark.skipif(HAS_OPENVINO, reason="the openvino provider is installed here")
def test_missing_openvino_says_how_to_install_it(tmp_path):
    with pytest.raises(
        MissingDependencyError, match="openvino provider is not available.*" + re.escape(install_hint("openvino"))
    ):
        load_pose_estimator(build_multipose_model(tmp_path / "m.onnx"), providers="openvino")


@needs_openvino
def test_auto_uses_openvino_when_installed(tmp_path):
    estimator = load_pose_estimator(build_multipose_model(tmp_path / "m.onnx"))
    assert estimator.model.provider == OPENVINO_PROVIDER
    # onnxruntime does not report the OpenVINO provider's options back (an empty dict), but it refuses unknown or
    # malformed ones (it would have fallen back to CPU, which OnnxModel turns into an error): these are the ones given
    options = estimator.model.provider_options[OPENVINO_PROVIDER]
    assert options == {"device_type": "CPU", "num_of_threads": str(estimator.model.threads), "precision": "FP32"}
    one = load_pose_estimator(build_multipose_model(tmp_path / "m.onnx"), threads=1, providers="openvino")
    assert one.model.provider == OPENVINO_PROVIDER
    assert one.model.provider_options[OPENVINO_PROVIDER]["num_of_threads"] == "1"


# Tolerances of the OpenVINO/CPU comparison, in input pixels of the 640x480 frame and in score units. The two
# providers run the same float32 graph with different kernels (fused convolutions, other summation orders), so
# outputs differ by rounding only: measured on the five-people frame, at most 0.0023 px and 2.2e-6 in score. A
# tolerance of 0.05 px (a twentieth of a pixel, far under the 2 px keypoint noise of docs/reproduction.md) and 1e-3
# in score catches any real difference (another precision such as FP16 or BF16 moves keypoints by 0.1-1 px).
KEYPOINT_TOLERANCE_PX = 0.05
SCORE_TOLERANCE = 1e-3


@needs_openvino
def test_openvino_gives_the_cpu_providers_keypoints():
    model = shared_path("models", "yolo11n-pose-256.onnx")
    color = cv2.cvtColor(cv2.imread(str(shared_path("data", "rgbd", "five_people", "color.png"))), cv2.COLOR_BGR2RGB)
    cpu = load_pose_estimator(model, providers="cpu")
    openvino = load_pose_estimator(model, providers="openvino")
    assert cpu.model.provider == CPU_PROVIDER and openvino.model.provider == OPENVINO_PROVIDER
    expected, got = cpu(color), openvino(color)
    assert len(expected) == len(got) == 5
    for a, b in zip(expected, got, strict=True):
        np.testing.assert_allclose(b.keypoints, a.keypoints, atol=KEYPOINT_TOLERANCE_PX)
        np.testing.assert_allclose(b.scores, a.scores, atol=SCORE_TOLERANCE)
        np.testing.assert_allclose(b.box, a.box, atol=KEYPOINT_TOLERANCE_PX)
        assert b.box_score == pytest.approx(a.box_score, abs=SCORE_TOLERANCE)


@pytest.mark.skipif(HAS_OPENVINO, reason="the openvino provider is installed here")
def test_openvino_overwritten_by_plain_onnxruntime_says_how_to_restore_it(monkeypatch):
    import importlib.metadata

    monkeypatch.setattr(importlib.metadata, "version", lambda name: "1.24.1")
    with pytest.raises(
        MissingDependencyError, match="onnxruntime-openvino 1.24.1 is installed, but the plain onnxruntime"
    ):
        resolve_providers("openvino")


LOAD_PROBE = """
import sys
from sid.perception.pose.session import OnnxModel
OnnxModel(sys.argv[1])  # the default: quiet
print("--", file=sys.stderr)
OnnxModel(sys.argv[1], load_warnings=True)  # asked for: onnxruntime's process-wide logger is back at warnings
"""


def test_onnxruntime_load_warnings_show_only_when_asked_for(tmp_path):
    """A Resize with an attribute deprecated since opset 13 (as YOLO11n-pose's exporter writes it): onnxruntime's
    process-wide logger warns while the session is created; each load runs in this subprocess, with a clean logger."""
    import subprocess
    import sys

    onnx = pytest.importorskip("onnx", reason="onnx builds the test model (the test extra)")
    from onnx import TensorProto, helper

    node = helper.make_node(
        "Resize", ["x", "roi", "scales"], ["y"], mode="nearest", coordinate_transformation_mode="tf_half_pixel_for_nn"
    )
    graph = helper.make_graph(
        [node],
        "resize",
        [helper.make_tensor_value_info("x", TensorProto.FLOAT, [1, 1, 4, 4])],
        [helper.make_tensor_value_info("y", TensorProto.FLOAT, None)],
        initializer=[
            helper.make_tensor("roi", TensorProto.FLOAT, [0], []),
            helper.make_tensor("scales", TensorProto.FLOAT, [4], [1, 1, 2, 2]),
        ],
    )
    path = tmp_path / "resize.onnx"
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)], ir_version=IR_VERSION)
    onnx.save(model, path)
    done = subprocess.run(
        [sys.executable, "-c", LOAD_PROBE, str(path)],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    quiet, asked = done.stderr.split("--\n")
    assert "onnxruntime" not in quiet and "tf_half_pixel_for_nn" in asked, done.stderr
