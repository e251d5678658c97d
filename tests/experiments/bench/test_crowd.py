"""``sid bench``'s crowd stages: the stacked real-crowd scene holds N people in every frame, copies never overlap,
groups stay whole; the records carry what was measured. No timing assertions."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sid.experiments.bench import QUICK, Context, RunSettings, benchmarks, run_suite, select
from sid.experiments.bench.crowd_scene import CrowdReplay, CrowdScene
from sid.experiments.bench.stages import CROWD_SETS, CROWD_SIZES
from sid.experiments.trajectories import load_trajectory_set
from tests.conftest import SHARED, shared_path
from tests.experiments.trajectory_files import write_set


def _staggered_set(folder: Path) -> Path:
    """A pair walking together (ids 1, 2) for all 40 steps (0.4 s each), and loners 3..8 for 10 steps each, one
    starting every 5 steps, all along +x at 1.2 m/s."""
    rows: list[tuple[float, ...]] = []
    for k in range(40):
        rows += [(k, 1, 0.48 * k, 0, 0.0, 1.2, 0, 0), (k, 2, 0.48 * k, 0, 0.6, 1.2, 0, 0)]
        for person in range(3, 9):
            start = 5 * (person - 3)
            if start <= k < start + 10:
                rows.append((k, person, 0.48 * (k - start), 0, 3.0, 1.2, 0, 0))
    return write_set(folder, rows, "1 2\n")


def _check_scene(scene: CrowdScene, n: int, frames: int) -> None:
    assert len(scene.frames) == frames
    assert (scene.present() >= n).all()
    for k, frame in enumerate(scene.frames):
        assert frame.timestamp == pytest.approx(k / scene.rate)
        ids = frame.truth_ids.tolist()
        assert len(set(ids)) == len(ids) and {p.id for p in frame.detections} <= set(ids)
    copies = np.concatenate([f.truth_ids for f in scene.frames]) // scene.id_stride
    positions = np.concatenate([f.truth_positions for f in scene.frames])
    boxes = [(positions[copies == c].min(axis=0), positions[copies == c].max(axis=0)) for c in np.unique(copies)]
    for a, (lo_a, hi_a) in enumerate(boxes):  # every copy in its own area of the ground
        for lo_b, hi_b in boxes[a + 1 :]:
            assert (hi_a < lo_b).any() or (hi_b < lo_a).any()


def test_a_scene_stacks_copies_until_n_are_present_and_keeps_groups_whole(tmp_path):
    replayed = CrowdReplay([load_trajectory_set(_staggered_set(tmp_path / "walk"))], rate=15.0)
    scene = replayed.scene(4, 30)
    _check_scene(scene, 4, 30)
    assert len(scene.copies) >= 2 and {c.name for c in scene.copies} == {"walk"}
    assert len({c.start for c in scene.copies}) == len(scene.copies), "disjoint stretches of the set"
    assert scene.present().min() == 4, "loners left out down to n"
    for frame in scene.frames:  # the pair of every copy is present in every frame
        in_set = frame.truth_ids % scene.id_stride
        for copy in range(len(scene.copies)):
            mine = in_set[frame.truth_ids // scene.id_stride == copy]
            assert {1, 2} <= set(mine.tolist())
    with pytest.raises(ValueError, match="fewer than 100 people"):
        replayed.scene(100, 30)


def test_a_scene_of_the_real_sets_holds_n_people_in_every_frame():
    sets = [load_trajectory_set(shared_path("data", "trajectories", name)) for name in CROWD_SETS]
    replayed = CrowdReplay(sets)
    scene = replayed.scene(60, 120)
    _check_scene(scene, 60, 120)
    assert {c.name for c in scene.copies} <= set(CROWD_SETS)
    lo, hi = scene.bounds()
    assert (hi - lo > replayed.tile).all(), "copies side by side in both directions"


def test_crowd_benchmarks_write_people_tracks_parts_and_the_reference():
    shared_path("data", "trajectories")
    ctx = Context(RunSettings(warmup=1, min_runs=2, max_runs=3, budget_s=1e-9), shared=SHARED, plan_runs=1)
    result = run_suite(select(benchmarks(ctx), "crowd"), ctx)
    assert not result.failures
    for n in CROWD_SIZES:
        stage = result.stages[f"crowd/{n}"]
        assert stage["runs"] == 2 and 0 <= stage["min_ms"] <= stage["median_ms"] <= stage["max_ms"]
        assert n <= stage["people"] <= stage["people_max"], "N people present in every measured frame"
        assert stage["tracks"] >= n // 2 and stage["copies"] >= 1 and stage["cells"] > 0
        assert stage.get("target_ms") == (10.0 if n == 100 else None)
        for part in ("people", "groups", "layer", "coherent"):
            assert result.stages[f"crowd/{n}/{part}"]["runs"] == 2
        reference = result.stages[f"crowd/{n}/coherent"]
        assert reference["ratio_to"] == f"crowd/{n}/groups" and reference["ratio"] > 0 and "groups" in reference


def test_crowd_benchmarks_are_skipped_with_a_note_without_the_sets(tmp_path):
    ctx = Context(QUICK, shared=tmp_path, plan_runs=1)
    names = [b.name for b in benchmarks(ctx)]
    assert not any(name.startswith("crowd/") for name in names)
    assert any("crowd benchmarks skipped: no trajectory set" in note for note in ctx.notes)
