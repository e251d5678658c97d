"""The pose benchmarks' options reach the pose sessions; bad ones are refused."""

from __future__ import annotations

import pytest

from tests.pose_models import build_multipose_model


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
