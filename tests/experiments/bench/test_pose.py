"""The pose benchmark helper returns per-stage medians in the documented shape (no timing assertions)."""

from __future__ import annotations

import numpy as np
import pytest

from sid.experiments.bench.pose import bench_pose
from tests.pose_models import build_multipose_model, build_singlepose_model

IMAGE = np.zeros((120, 160, 3), np.uint8)
STAGES = {"preprocess_ms", "inference_ms", "postprocess_ms", "total_ms"}


def test_whole_image_stages(tmp_path):
    result = bench_pose(build_multipose_model(tmp_path / "m.onnx"), IMAGE, runs=3, threads=1)
    assert result["contract"] == "movenet_multipose" and result["runs"] == 3 and result["threads"] == 1
    assert result["input_size"] == (192, 256)  # 256 on the long side
    assert set(result["image"]) >= STAGES and result["image"]["people"] == 0
    assert all(result["image"][k] > 0 for k in STAGES)
    assert "crops" not in result


def test_singlepose_crop_counts(tmp_path):
    result = bench_pose(
        build_singlepose_model(tmp_path / "s.onnx"), IMAGE, runs=2, boxes=[[10, 10, 50, 100]], crop_counts=(2, 3)
    )
    assert set(result["crops"]) == {2, 3}
    for count, times in result["crops"].items():
        assert set(times) >= STAGES
        assert times["per_crop_total_ms"] == pytest.approx(times["total_ms"] / count)
    assert set(bench_pose(tmp_path / "s.onnx", IMAGE, runs=1, crop_counts=(4,))["crops"]) == {4}  # strips


def test_bad_runs_are_refused(tmp_path):
    with pytest.raises(ValueError, match="runs"):
        bench_pose(build_multipose_model(tmp_path / "m.onnx"), IMAGE, runs=0)


def test_bench_context_sets_the_pose_sessions_threads_and_provider(tmp_path):
    from sid.experiments.bench import QUICK, Context, benchmarks

    (tmp_path / "models").mkdir()
    build_multipose_model(tmp_path / "models" / "m.onnx")
    ctx = Context(QUICK, shared=tmp_path, plan_runs=1, pose_threads=1, pose_provider="cpu")
    (item,) = [b for b in benchmarks(ctx) if b.name == "pose/m"]
    record = item.run(ctx)["pose/m"]
    assert record["threads"] == 1 and record["provider"] == "CPUExecutionProvider"
    (estimator,) = [v for k, v in ctx._cache.items() if k.startswith("estimator/")]
    options = estimator.model.session.get_session_options()
    assert options.intra_op_num_threads == 1
    assert options.get_session_config_entry("session.intra_op.allow_spinning") == "0"


@pytest.mark.parametrize("option", [["--threads", "0"], ["--provider", "tpu"]])
def test_bench_refuses_bad_pose_options(option, capsys):
    from sid.cli import main

    with pytest.raises(SystemExit) as info:
        main(["bench", "--list", *option])
    assert info.value.code == 2
    assert option[0] in capsys.readouterr().err
