"""``sid bench``: the command runs end to end on tiny settings and writes the documented fields; ``--compare``;
the stage selection; the timing harness's bookkeeping; the authors' grouping baseline against our detector.

No timing assertions: only what was measured and written, never how fast.
"""

from __future__ import annotations

import gc
import json
import math

import numpy as np
import pytest

from sid.cli import main
from sid.experiments.bench import (
    QUICK,
    BaselineParams,
    Benchmark,
    Context,
    RunSettings,
    Stats,
    baseline_groups,
    benchmarks,
    format_comparison,
    grouping_scene,
    load_report,
    measure_parts,
    run_suite,
    select,
)
from sid.experiments.bench.report import PAPER_COLUMN
from sid.perception.cluster import dbscan_labels
from sid.perception.groups import GroupParams, detect_groups
from sid.perception.people import Person
from tests.conftest import shared_path

FIXED = ("median_ms", "min_ms", "max_ms", "runs")
MACHINE = ("cpu", "logical_cores", "physical_cores", "usable_cores", "load_average", "python", "numpy", "scipy",
           "scikit-learn", "shapely", "onnxruntime", "ompl", "date")  # fmt: skip


def _check_stage(stage: dict) -> None:
    assert all(key in stage for key in FIXED)
    assert stage["runs"] >= 1
    assert 0 <= stage["min_ms"] <= stage["median_ms"] <= stage["max_ms"]


def test_quick_run_writes_documented_fields(tmp_path, capsys):
    out = tmp_path / "bench"
    rc = main(["bench", "--quick", "--only", "group/2,group_baseline/4,dbscan_sklearn/4,costmap/inflation",
               "--out", str(out)])  # fmt: skip
    assert rc == 0
    report = json.loads((out / "bench.json").read_text())
    assert report["format"] == "sid-bench/1"
    assert all(key in report["machine"] for key in MACHINE)
    assert report["machine"]["logical_cores"] >= 1
    assert report["settings"]["quick"] is True
    # group_baseline/4 and dbscan_sklearn/4 bring the stages their ratios refer to
    stages = report["stages"]
    assert set(stages) == {
        "group/2",
        "group/4",
        "group_baseline/4",
        "dbscan/4",
        "dbscan_sklearn/4",
        "costmap/inflation",
    }
    for stage in stages.values():
        _check_stage(stage)
    baseline = stages["group_baseline/4"]
    assert baseline["ratio_to"] == "group/4"
    assert baseline["ratio"] == pytest.approx(baseline["median_ms"] / stages["group/4"]["median_ms"])
    assert baseline["same_groups"] is True and baseline["groups"] == 1
    assert stages["dbscan_sklearn/4"]["same_labels"] is True
    assert stages["group/2"]["paper_ms"] == 0.25
    assert stages["costmap/inflation"]["cells"] == 400 * 400
    md = (out / "bench.md").read_text()
    assert PAPER_COLUMN in md
    assert "| group/2 |" in md and "| 0.25 |" in md
    assert "| group/2 |" in capsys.readouterr().out


def test_groups_from_positions_alone_are_timed_beside_the_default_on_the_scene_without_facings(tmp_path):
    rc = main(["bench", "--quick", "--only", "group_positions_only/20", "--out", str(tmp_path / "bench")])
    assert rc == 0
    stages = json.loads((tmp_path / "bench" / "bench.json").read_text())["stages"]
    assert set(stages) == {"group/20", "group_positions_only/20"}
    stage = stages["group_positions_only/20"]
    _check_stage(stage)
    # Five circles of four, 2.4 m apart: positions alone find each, as the facings do.
    assert stage["ratio_to"] == "group/20" and stage["groups"] == 5 and stage["circles_found"] == 5


def test_compare_prints_change_per_stage(tmp_path, capsys):
    old = tmp_path / "old.json"
    old.write_text(json.dumps({
        "machine": {"cpu": "another cpu"},
        "stages": {"dbscan/4": {"median_ms": 1000.0, "min_ms": 900.0, "max_ms": 1100.0, "runs": 3},
                   "retired/stage": {"median_ms": 1.0, "min_ms": 1.0, "max_ms": 1.0, "runs": 1}},
    }))  # fmt: skip
    out = tmp_path / "new"
    assert main(["bench", "--quick", "--only", "dbscan/4", "--out", str(out), "--compare", str(old)]) == 0
    printed = capsys.readouterr().out
    row = next(line for line in printed.splitlines() if line.startswith("dbscan/4 "))
    new_ms = load_report(out / "bench.json")["stages"]["dbscan/4"]["median_ms"]
    assert f"{new_ms / 1000.0:.2f}" in row and "faster" in row
    assert "1 stage of the old report not selected by --only" in printed
    assert "different machines" in printed
    assert "Change against the earlier report" in (out / "bench.md").read_text()
    full_run = load_report(out / "bench.json") | {"settings": {"only": None}}
    listed = format_comparison(json.loads(old.read_text()), full_run)
    assert "only in the old report: retired/stage" in listed


def test_bad_compare_file_and_unknown_stage_are_clear_errors(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    for median in ('"fast"', "NaN", "0"):  # a ratio against NaN or 0 printed "nan" or "inf slower"
        bad.write_text('{"stages": {"x": {"median_ms": ' + median + "}}}")
        assert main(["bench", "--quick", "--compare", str(bad), "--out", str(tmp_path)]) == 2
        assert "stage 'x' has no positive \"median_ms\"" in capsys.readouterr().err
    assert main(["bench", "--quick", "--compare", str(tmp_path / "missing.json"), "--out", str(tmp_path)]) == 2
    assert "cannot read" in capsys.readouterr().err
    assert main(["bench", "--quick", "--only", "nothing/here", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "matches no benchmark" in err and "group/20" in err
    assert not (tmp_path / "bench.json").exists()
    # A report the comparison cannot read ("machine": null) passed, and the comparison failed after the whole run,
    # writing nothing; a thread count or a provider sid detect refuses ran every pose stage into a traceback.
    bad.write_text('{"stages": {"x": {"median_ms": 1}}, "machine": null}')
    assert main(["bench", "--quick", "--compare", str(bad), "--out", str(tmp_path)]) == 2
    assert '"machine" must be an object, got null' in capsys.readouterr().err
    assert main(["bench", "--quick", "--threads", "100000", "--out", str(tmp_path)]) == 2
    assert "pose: threads must be at most" in capsys.readouterr().err
    assert not (tmp_path / "bench.json").exists()


def _context(tmp_path, settings: RunSettings = QUICK) -> Context:
    return Context(settings, shared=tmp_path / "no-shared", plan_runs=1)


def test_selection_patterns_and_missing_models_note(tmp_path):
    ctx = _context(tmp_path)
    items = benchmarks(ctx)
    names = [b.name for b in items]
    assert not any(n.startswith("pose/") for n in names)
    assert any("pose benchmarks skipped" in note for note in ctx.notes)
    assert [b.name for b in select(items, "group")] == [f"group/{n}" for n in (2, 3, 4, 6, 20, 100)]
    assert [b.name for b in select(items, "group_rays/100")] == ["group/100", "group_rays/100"]
    assert "group_paper/100" not in [b.name for b in items] and "group_baseline/20" in [b.name for b in items]
    assert [b.name for b in select(items, "group_baseline/6")] == ["group/6", "group_baseline/6"]
    assert [b.name for b in select(items, "align/*")] == [
        "align/rectangle",
        "align/point",
        "align/sparse_4x17",
        "align/window_4x17",
    ]
    assert len(select(items, None)) == len(items)
    with pytest.raises(ValueError, match="matches no benchmark"):
        select(items, "pose")


def test_a_failing_benchmark_is_reported_and_the_others_kept(tmp_path):
    ctx = _context(tmp_path)

    def broken(_: Context) -> dict:
        raise RuntimeError("model file is corrupt")

    items = [Benchmark("broken", "raises", broken), *select(benchmarks(ctx), "dbscan/4")]
    result = run_suite(items, ctx)
    assert result.failures == {"broken": "RuntimeError: model file is corrupt"}
    assert "broken failed: RuntimeError: model file is corrupt" in ctx.notes
    _check_stage(result.stages["dbscan/4"])


def test_harness_counts_runs_and_restores_the_collector():
    calls = []
    settings = RunSettings(warmup=2, min_runs=4, max_runs=6, budget_s=1e-9)
    parts = measure_parts(lambda: calls.append(1) or {"a": 1.0, "b": 2.0}, settings)
    assert len(calls) == 2 + 4  # warm-up, then min_runs since the budget is spent at once
    assert parts["a"] == Stats(1.0, 1.0, 1.0, 4) and parts["b"].median_ms == 2.0
    assert gc.isenabled()
    settings = RunSettings(warmup=0, min_runs=1, max_runs=3, budget_s=60.0)
    assert measure_parts(lambda: {"a": 0.0}, settings)["a"].runs == 3
    turns = iter([{"a": 1.0, "b": 2.0}, {"b": 2.0, "a": 1.0}, {"a": 1.0, "b": 2.0}])
    assert measure_parts(lambda: next(turns), settings)["b"] == Stats(2.0, 2.0, 2.0, 3)  # parts timed in turns
    with pytest.raises(ValueError, match="min_runs"):
        RunSettings(warmup=0, min_runs=5, max_runs=2, budget_s=1.0)


@pytest.mark.parametrize(
    ("replies", "message"),
    [
        ([{}], "reported no parts"),  # looped forever: the stop counted the first part's samples
        ([{"a": 1.0}, {"b": 1.0}], r"reported parts \['b'\], an earlier one \['a'\]"),
        ([{"a": 1.0, "b": 2.0}, {"b": 2.0}], r"reported parts \['b'\], an earlier one \['a', 'b'\]"),
    ],
)
def test_harness_refuses_calls_without_parts_or_with_other_parts(replies, message):
    import signal

    calls = iter(range(10**6))

    def fn() -> dict[str, float]:
        return replies[min(next(calls), len(replies) - 1)]

    def stop(*_: object) -> None:
        raise TimeoutError("measure_parts did not return")

    previous = signal.signal(signal.SIGALRM, stop)
    signal.alarm(10)
    try:
        for warmup in (0, 1):
            with pytest.raises(ValueError, match=message):
                calls = iter(range(10**6))
                measure_parts(fn, RunSettings(warmup=warmup, min_runs=1, max_runs=5, budget_s=60.0))
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


@pytest.mark.parametrize("method", ["ospace", "rays"])
def test_grouping_scene_is_seeded_one_crowd_of_circles(method):
    people = grouping_scene(20)
    assert len(people) == 20 and len({p.id for p in people}) == 20
    assert [(p.x, p.theta) for p in people] == [(p.x, p.theta) for p in grouping_scene(20)]
    labels = dbscan_labels(np.array([[p.x, p.y] for p in people]), GroupParams().eps, GroupParams().min_samples)
    assert set(labels.tolist()) == {0}, "one crowd"
    found = [g.members for g in detect_groups(people, GroupParams(method=method))]
    assert sorted(found) == [tuple(range(k, k + 4)) for k in range(0, 20, 4)]


# --- the authors' approach against ours on easy scenes ------------------------------------------------------------


def _facing_pair() -> list[Person]:
    """Two people 0.8 m apart facing each other, both turned 3 degrees so that their rays cross (exactly opposite
    rays overlap in a segment, which the authors' intersection test does not count)."""
    turn = math.radians(3.0)
    return [Person(1, 2.0, 0.4, -math.pi / 2 + turn, 1.0), Person(2, 2.0, -0.4, math.pi / 2 - turn, 1.0)]


def _circle(n: int, radius: float, centre=(2.5, 0.0), jitter_deg: float = 3.0, seed: int = 0) -> list[Person]:
    rng = np.random.default_rng(seed)
    people = []
    for k in range(n):
        a = 2 * math.pi * k / n + 0.3
        x, y = centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a)
        theta = math.atan2(centre[1] - y, centre[0] - x) + math.radians(rng.normal(0.0, jitter_deg))
        people.append(Person(k + 1, x, y, theta, 1.0))
    return people


@pytest.mark.parametrize("prune", [True, False])
@pytest.mark.parametrize("scene", [_facing_pair(), _circle(4, 0.8)], ids=["pair", "circle4"])
def test_baseline_finds_the_same_groups_as_our_detector(scene, prune):
    ours = detect_groups(scene)
    theirs = baseline_groups(scene, BaselineParams(prune=prune))
    assert [g.members for g in theirs] == [g.members for g in ours] == [tuple(p.id for p in scene)]
    # Interest points: both near the centre of the conversation (ours uses the midpoint for a face-to-face pair).
    np.testing.assert_allclose(theirs[0].interest_point, ours[0].interest_point, atol=0.05)
    assert theirs[0].area < BaselineParams().area_threshold and theirs[0].spread < 3.0


def test_baseline_pruning_drops_a_passer_by():
    """A triangle facing its centre and a fourth person 2 m away looking across it: the fourth ray's crossings
    spread the hull far beyond 0.5 m^2; the paper's pruning removes that person, the authors' node finds nothing."""
    trio = _circle(3, 0.69, jitter_deg=0.0)
    passer = Person(9, 2.5, 2.5, math.radians(-60.0), 1.0)
    scene = [*trio, passer]
    pruned = baseline_groups(scene)
    assert [g.members for g in pruned] == [(1, 2, 3)]
    np.testing.assert_allclose(pruned[0].interest_point, (2.5, 0.0), atol=1e-6)
    assert baseline_groups(scene, BaselineParams(prune=False)) == []


def test_baseline_rejects_bad_input_and_ignores_unknown_facing():
    with pytest.raises(ValueError, match="person 2 has a non-finite pose"):
        baseline_groups([Person(1, 0.0, 0.0, 0.0), Person(2, float("nan"), 0.0, 0.0)])
    assert baseline_groups([Person(1, 0.0, 0.0, None), Person(2, 1.0, 0.0, math.pi)]) == []


def test_pose_stage_on_the_real_models(tmp_path):
    models = shared_path("models")
    if not (models / "yolo11n-pose-256.onnx").exists():
        pytest.skip(f"{models / 'yolo11n-pose-256.onnx'} is absent")
    shared_path("data", "rgbd", "five_people", "color.png")
    out = tmp_path / "bench"
    assert main(["bench", "--quick", "--only", "pose/yolo11n-pose-256", "--out", str(out)]) == 0
    stages = load_report(out / "bench.json")["stages"]
    total = stages["pose/yolo11n-pose-256"]
    _check_stage(total)
    assert total["contract"] == "yolo_pose" and total["people"] == 5
    for part in ("preprocess", "session_run", "postprocess"):
        _check_stage(stages[f"pose/yolo11n-pose-256/{part}"])


def test_int8_pose_stage_times_both_models_in_the_same_calls_and_checks_the_results(tmp_path):
    model = shared_path("models", "yolo11n-pose-256.onnx")
    shared_path("data", "rgbd", "hero")
    out = tmp_path / "bench"
    assert main(["bench", "--quick", "--only", f"pose_int8/{model.stem}", "--out", str(out)]) == 0
    stages = load_report(out / "bench.json")["stages"]
    int8 = stages[f"pose_int8/{model.stem}"]
    for name in ("", "/float", "/simplified"):
        _check_stage(stages[f"pose_int8/{model.stem}{name}"])
    float_ms = stages[f"pose_int8/{model.stem}/float"]["median_ms"]
    assert int8["runs"] == stages[f"pose_int8/{model.stem}/float"]["runs"]  # one sample of each per call
    assert int8["speedup"] == pytest.approx(float_ms / int8["median_ms"])
    assert int8["calibration_frames"] == int8["compared_frames"] == 6  # five_people and the five hero frames
    assert int8["frames_with_other_results"] == 0 and int8["lowest_mean_oks"] >= 0.9
    assert int8["box_branch_nodes"] > 0  # YOLO's box regression quantized whole (docs/models.md)


def test_frame_and_lift_stages_without_shared_data(tmp_path):
    """Without ../shared the per-frame pipeline still runs, with TruthPose as its pose stage, and says so."""
    out = tmp_path / "bench"
    rc = main(["bench", "--quick", "--only", "frame/2,lift/4", "--shared", str(tmp_path / "none"), "--out", str(out)])
    assert rc == 0
    report = load_report(out / "bench.json")
    frame = report["stages"]["frame/2"]
    _check_stage(frame)
    assert frame["pose"] == "TruthPose" and frame["people"] == 2 and frame["groups"] == 1
    assert frame["paper_ms"] == 3.95
    for part in ("pose", "lift", "group"):
        _check_stage(report["stages"][f"frame/2/{part}"])
    assert report["stages"]["lift/4"]["people"] == 4
    assert any("pose = TruthPose" in note for note in report["notes"])


def test_render_stage_casts_every_timed_frame_and_noise_stage_reuses_the_render(tmp_path, monkeypatch):
    """``synthetic/render`` times a fresh ray cast per call (not the camera's kept render); ``synthetic/noise``
    times the kept-render path, which casts only while building the first frame."""
    from sid.synthetic import render as render_module

    casts = []
    original = render_module.RayCaster.render
    monkeypatch.setattr(
        render_module.RayCaster, "render", lambda self, *a, **k: casts.append(1) or original(self, *a, **k)
    )
    settings = RunSettings(warmup=1, min_runs=3, max_runs=3, budget_s=1e-9)
    ctx = _context(tmp_path, settings)
    items = benchmarks(ctx)
    stages = run_suite(select(items, "synthetic/render"), ctx).stages
    assert stages["synthetic/render"]["runs"] == 3
    assert len(casts) >= 1 + 3 + 3  # the empty floor, then at least one cast per call (warm-up and timed)
    casts.clear()
    stages = run_suite(select(items, "synthetic/noise"), ctx).stages
    _check_stage(stages["synthetic/noise"])
    first_frame = len(casts)
    assert first_frame >= 1
    casts.clear()
    from sid.experiments.bench.stages.inputs import frame_scene
    from sid.synthetic import SyntheticCamera

    camera, scene = SyntheticCamera(), frame_scene(4)
    camera.capture(scene, index=0)
    assert len(casts) == first_frame  # the noise stage's 4 calls cast no more than one frame needs


def test_compare_shows_minimums_and_warns_about_other_settings_and_other_work():
    def report(quick: bool, provider: str, pose: str, min_ms: float) -> dict:
        return {
            "machine": {"cpu": "same cpu"},
            "settings": {"quick": quick, "pose_provider": provider, "pose_threads": 2, "plan_runs": 5},
            "stages": {
                "frame/4": {"median_ms": 10.0, "min_ms": min_ms, "max_ms": 12.0, "runs": 9, "pose": pose},
                "pose/m": {"median_ms": 5.0, "min_ms": 4.0, "max_ms": 6.0, "runs": 9, "provider": provider},
            },
        }

    same = format_comparison(report(False, "cpu", "yolo", 8.0), report(False, "cpu", "yolo", 7.5))
    assert "warning" not in same
    header, row = same.splitlines()[0].split(), next(r for r in same.splitlines() if r.startswith("frame/4 ")).split()
    assert header == ["stage", "old", "median", "new", "median", "new/old", "old", "min", "new", "min"]
    assert row == ["frame/4", "10.000", "10.000", "1.00", "8.000", "7.500"]
    changed = format_comparison(report(False, "cpu", "yolo", 8.0), report(True, "cuda", "TruthPose", 8.0))
    assert "warning: different run settings (quick False -> True; pose_provider 'cpu' -> 'cuda')" in changed
    assert "warning: frame/4 timed other work (pose 'yolo' -> 'TruthPose')" in changed
    assert "warning: pose/m timed other work (provider 'cpu' -> 'cuda')" in changed
