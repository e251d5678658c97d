"""Sweeps: in this process, in worker processes and on a local Ray instance give the same per-run results."""

import json
import os

import pytest

from sid.experiments.simulate.loop import RunOptions
from sid.experiments.simulate.report import write_sweep_report
from sid.experiments.simulate.sweep import run_sweep, sweep_jobs, sweep_summary
from tests.experiments.simulate.tiny import TINY


@pytest.fixture
def scene(tmp_path):
    data = TINY | {"simulation": {"max_speed": 1.0, "time_limit_s": 1.0}}
    path = tmp_path / "tiny.json"
    path.write_text(json.dumps(data))
    return str(path)


def _comparable(records):
    return [{k: v for k, v in r.items() if k != "planning_time_s"} for r in records]


def test_jobs_cover_scenes_modes_and_seeds(scene):
    jobs = sweep_jobs([scene, "pair"], 2, RunOptions(perception="exact"))
    assert len(jobs) == 8
    assert {(j.scene, j.options.social, j.options.seed) for j in jobs} == {
        (s, social, seed) for s in (scene, "pair") for social in (False, True) for seed in (1, 2)
    }
    assert all(j.options.perception == "exact" for j in jobs)
    with pytest.raises(ValueError, match="seeds must be"):
        sweep_jobs([scene], 0)
    with pytest.raises(ValueError, match="built-in scene"):
        sweep_jobs(["nowhere"], 1)
    with pytest.raises(ValueError, match="sweep: scene pair is given twice"):  # its runs were counted twice
        sweep_jobs(["pair", scene, "pair"], 1)


def test_workers_give_the_same_runs_as_one_process(scene, tmp_path):
    jobs = sweep_jobs([scene], 1, RunOptions(perception="exact"))
    alone = run_sweep(jobs)
    pooled = run_sweep(jobs, workers=2)
    assert _comparable(pooled) == _comparable(alone)
    assert [r["social_layer"] for r in alone] == [False, True]
    rows = sweep_summary(alone)
    assert [row["social_layer"] for row in rows] == [False, True]
    assert all(row["runs"] == 1 and row["collision_rate"] == 0 for row in rows)
    paths = write_sweep_report(alone, tmp_path / "out", "sid simulate --sweep tiny", 1.0, "1 worker process(es)")
    assert all(p.is_file() for p in paths.values())
    assert "| all | without | 1 |" in paths["md"].read_text()


def test_a_local_ray_instance_gives_the_same_runs(scene):
    """On the Ray head at $SID_RAY_ADDRESS (e.g. one ``ray start --head`` started), else on a Ray instance started
    here for the test."""
    pytest.importorskip("ray")
    jobs = sweep_jobs([scene], 1, RunOptions(perception="exact"))
    address = os.environ.get("SID_RAY_ADDRESS", "local")
    assert _comparable(run_sweep(jobs, ray_address=address)) == _comparable(run_sweep(jobs))


def test_the_mean_closest_approach_is_over_the_successful_runs_as_the_median_and_worst():
    def run(seed: int, success: bool, distance: float) -> dict:
        return {
            "scene": "s",
            "seed": seed,
            "social_layer": True,
            "success": success,
            "collisions": int(not success),
            "time_to_goal_s": 10.0 if success else None,
            "planning_time_s": 0.1,
            "ospace_intrusion_m": 0.0,
            "crosses_group": False,
            "min_person_distance_m": distance,
            "length_ratio": 1.1 if success else None,
        }

    (row,) = sweep_summary([run(0, True, 1.0), run(1, True, 1.4), run(2, False, 0.1)])
    assert row["median_min_person_distance_m"] == pytest.approx(1.2) and row["worst_min_person_distance_m"] == 1.0
    assert row["mean_min_person_distance_m"] == pytest.approx(1.2)  # the collision's 0.1 m is left out of all three
    assert row["collision_rate"] == pytest.approx(1 / 3)
