"""``sid model``: bad input ends in one line and exit 2; the real YOLO11n-pose quantized and compared end to end
(skipped when ../shared is absent)."""

from __future__ import annotations

import json
import re
import sys

import numpy as np
import pytest

from sid.cli import main
from sid.cli.common import ExitCode
from sid.distribution import install_hint
from sid.perception.pose import load_pose_estimator
from tests.conftest import shared_path
from tests.pose_models import build_yolo_pose_model

INTRINSICS = {"fx": 500.0, "fy": 500.0, "cx": 31.5, "cy": 23.5, "width": 64, "height": 48}


def _error(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert err and err[0].startswith("sid model ") and err[0].count("sid model") == 1  # the command named once
    return err[0]


def test_a_missing_model_is_named(tmp_path, capsys):
    code = main(["model", "quantize", str(tmp_path / "nope.onnx"), str(tmp_path / "out.onnx"),
                 "--calibrate", "synthetic:S1", "--frames", "1"])  # fmt: skip
    assert code == 2 and "pose model file not found" in _error(capsys)
    assert not (tmp_path / "out.onnx").exists()


def test_an_output_in_a_missing_folder_is_named_before_any_work(tmp_path, capsys):
    model = build_yolo_pose_model(tmp_path / "tiny.onnx", np.zeros((56, 4), np.float32))
    code = main(["model", "quantize", str(model), str(tmp_path / "no" / "out.onnx"), "--calibrate", "synthetic:S1"])
    assert code == 2 and f"the folder {tmp_path / 'no'} does not exist" in _error(capsys)
    assert main(["model", "simplify", str(model), str(model)]) == 2 and "is the input model" in _error(capsys)


def test_a_negative_layer_count_is_a_usage_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["model", "quantize", "a.onnx", "b.onnx", "--calibrate", "synthetic:S1", "--float-layers", "-1"])
    assert stop.value.code == 2 and "expected a whole number >= 0, got '-1'" in capsys.readouterr().err


def test_a_file_that_is_not_a_model_is_named(tmp_path, capsys):
    fake = tmp_path / "fake.onnx"
    fake.write_text("not a model")
    code = main(["model", "compare", str(fake), str(fake), "--source", "synthetic:S1", "--frames", "1"])
    assert code == 2 and "is not an ONNX model" in _error(capsys)


def test_a_source_without_frames_is_named(tmp_path, capsys):
    model = build_yolo_pose_model(tmp_path / "tiny.onnx", np.zeros((56, 4), np.float32))
    empty = tmp_path / "frames"
    (empty / "color").mkdir(parents=True)  # a sequence layout without a single frame
    (empty / "depth").mkdir()
    (empty / "intrinsics.json").write_text(json.dumps(INTRINSICS))
    code = main(["model", "quantize", str(model), str(tmp_path / "out.onnx"), "--calibrate", str(empty)])
    assert code == 2 and "hold no images" in _error(capsys)
    (empty / "color" / "a.png").write_bytes(b"not a png")  # one frame, unreadable: skipped, then none is left
    (empty / "depth" / "a.png").write_bytes(b"not a png")
    code = main(["model", "quantize", str(model), str(tmp_path / "out.onnx"), "--calibrate", str(empty)])
    err = capsys.readouterr().err.strip().splitlines()
    # the frame named as the results name it, DIR#N
    assert code == 2 and err[0].startswith(f"sid model quantize: {empty}#0: skipped, ")
    assert err[-1].startswith(f"sid model quantize: no frames in {empty}")
    code = main(["model", "quantize", str(model), str(tmp_path / "out.onnx"), "--calibrate", str(tmp_path / "x")])
    assert code == 2 and "no such file or directory" in _error(capsys)


def test_a_model_with_nothing_to_quantize_is_named(tmp_path, capsys):
    model = build_yolo_pose_model(tmp_path / "tiny.onnx", np.zeros((56, 4), np.float32))
    code = main(["model", "quantize", str(model), str(tmp_path / "out.onnx"), "--calibrate", "synthetic:S1",
                 "--frames", "1"])  # fmt: skip
    assert code == 2 and "no Conv" in _error(capsys)


def test_without_onnx_each_task_says_which_extra_to_install(tmp_path, capsys, monkeypatch):
    model = build_yolo_pose_model(tmp_path / "tiny.onnx", np.zeros((56, 4), np.float32))
    monkeypatch.setitem(sys.modules, "onnx", None)  # import onnx now raises ImportError, as without the extra
    for task, *rest in (["simplify"], ["quantize", "--calibrate", "synthetic:S1", "--frames", "1"]):
        code = main(["model", task, str(model), str(tmp_path / "out.onnx"), *rest])
        line = _error(capsys)
        assert code == ExitCode.MISSING_DEPENDENCY and line.startswith(f"sid model {task}: ")
        assert install_hint("quantize") in line and not (tmp_path / "out.onnx").exists()


def test_simplify_writes_a_model_with_the_same_contract(tmp_path, capsys):
    model = build_yolo_pose_model(tmp_path / "tiny.onnx", np.zeros((56, 4), np.float32))
    assert main(["model", "simplify", str(model), str(tmp_path / "simple.onnx")]) == 0
    assert "0 no-op node(s) removed" in capsys.readouterr().out
    assert load_pose_estimator(tmp_path / "simple.onnx").contract == "yolo_pose"


@pytest.mark.slow
def test_quantize_then_compare_the_real_yolo_model(tmp_path, capsys):
    model = shared_path("models", "yolo11n-pose-256.onnx")
    frames = [
        str(shared_path("data", "rgbd", "five_people")),
        str(shared_path("data", "rgbd", "hero", "hero_12-42-25")),
    ]
    out = tmp_path / "int8.onnx"
    code = main(["model", "quantize", str(model), str(out), "--calibrate", *frames])
    assert code in (ExitCode.OK, ExitCode.DIFFERENT)
    printed = capsys.readouterr().out
    assert f"wrote {out}: yolo_pose, INT8" in printed and "calibrated on 2 frame(s)" in printed
    assert re.search(r"nodes quantized \(\d+ of them in the box branch\)", printed)  # 26 with onnxruntime 1.32
    boxes = tmp_path / "int8-float-boxes.onnx"
    main(["model", "quantize", str(model), str(boxes), "--calibrate", *frames, "--float-boxes"])
    assert "box branch" not in capsys.readouterr().out
    assert out.stat().st_size != boxes.stat().st_size  # the box branch's weights in int8: a smaller file
    code = main(["model", "compare", str(model), str(out), "--source", frames[0]])
    table = capsys.readouterr().out
    assert code in (ExitCode.OK, ExitCode.DIFFERENT) and "| five_people#0 |" not in table
    assert f"| {frames[0]}#0 | 5 / 5 | 5 / 5 |" in table
    assert load_pose_estimator(out).contract == "yolo_pose"


def test_bag_topics_are_options_here_too_and_refused_for_a_source_without_topics(tmp_path, capsys):
    model = build_yolo_pose_model(tmp_path / "yolo.onnx", np.zeros((56, 10)))
    code = main(["model", "compare", str(model), str(model), "--source", "synthetic:S1", "--color-topic", "/x/image"])
    assert code == 2
    assert _error(capsys) == (
        "sid model compare: --color-topic: only rosbag2 recordings have topics to choose, and synthetic:S1 is not one"
    )
