"""Sweeps of simulated runs: scenes x without / with the social layer x seeds, in parallel worker processes or on a
Ray cluster, summarised with the one with/without harness (``sid.experiments.harness.summarise``).

A job is (scene, social layer, seed) plus the options shared by the sweep; its result is the run's record
(``sid.experiments.simulate.run.run_record``) without the trajectory, which is replaced by ``trajectory_sha256``
(a digest of its rounded rows), so that two sweeps can be compared run by run cheaply. Results come back in job
order whatever the executor, and a run depends only on its job (noise from ``[seed, step]``), so the same sweep
gives the same per-run results in one process, in workers and on Ray.
"""

from __future__ import annotations

import hashlib
import json
import os
import statistics
import sys
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from sid.checks import Limits, check_whole, limits, repeated, use_limits
from sid.cpu import keep_freed_memory
from sid.distribution import MissingDependencyError, install_hint
from sid.errors import InputError
from sid.experiments.harness import summarise
from sid.experiments.progress import Progress
from sid.experiments.simulate.loop import RunOptions
from sid.experiments.simulate.run import run_record
from sid.experiments.simulate.scenes import load_scene
from sid.experiments.workers import map_in_workers

__all__ = ["Job", "run_job", "run_sweep", "sweep_jobs", "sweep_summary"]


@dataclass(frozen=True)
class Job:
    """One run of a sweep: the scene (built-in name or file path) and the options (social layer, seed, ...)."""

    scene: str
    options: RunOptions

    def describe(self) -> str:
        mode = "with" if self.options.social else "without"
        return f"{self.scene} {mode} seed {self.options.seed}"


def sweep_jobs(scenes: Sequence[str], seeds: int, options: RunOptions | None = None) -> list[Job]:
    """Every scene x seeds 1..``seeds`` x without / with the social layer (other options from ``options``)."""
    options = options or RunOptions()
    check_whole("sweep", "seeds", seeds, low=1)
    for scene in scenes:
        load_scene(scene)  # a bad scene fails here, before any run
    twice = repeated(list(scenes))
    if twice is not None:  # the summary would count its runs twice
        raise InputError(f"sweep: scene {twice} is given twice")
    return [
        Job(scene, replace(options, social=social, seed=seed))
        for scene in scenes
        for seed in range(1, int(seeds) + 1)
        for social in (False, True)
    ]


def run_job(job: Job) -> dict[str, Any]:
    """The record of one job (module docstring); what every executor runs."""
    record = run_record(load_scene(job.scene), job.options)
    trajectory = record.pop("trajectory")
    record["trajectory_sha256"] = hashlib.sha256(json.dumps(trajectory).encode()).hexdigest()
    record["scene"] = job.scene
    return record


def _worker_job(job: Job, in_force: Limits) -> dict[str, Any]:
    """``run_job`` on Ray, with the allocator set as the ``sid`` command sets it and the parent's limits in force
    (``sid.checks.use_limits``: a fresh interpreter starts with the defaults)."""
    keep_freed_memory()
    with use_limits(in_force):
        return run_job(job)


def _job_task(_: None, job: Job) -> dict[str, Any]:
    return run_job(job)


def _in_process(jobs: Sequence[Job], progress: Progress | None) -> list[dict]:
    out = []
    for i, job in enumerate(jobs):
        if progress:
            progress(i, len(jobs), job.describe())
        out.append(run_job(job))
    return out


def _on_ray(jobs: Sequence[Job], address: str, progress: Progress | None) -> list[dict]:
    try:
        import ray
    except ImportError:
        raise MissingDependencyError(f"sweep: running on Ray needs Ray: {install_hint('cluster')}") from None
    root = str(Path(__file__).resolve().parents[3])  # where the sid, costmap and planner packages live
    paths = os.pathsep.join([root, *(p for p in sys.path if p)])
    started = not ray.is_initialized()
    if started:
        kwargs: dict[str, Any] = {"runtime_env": {"env_vars": {"PYTHONPATH": paths}}, "log_to_driver": False}
        if address == "local":
            ray.init(include_dashboard=False, **kwargs)
        else:
            ray.init(address=address, **kwargs)
    try:
        remote = ray.remote(num_cpus=1)(_worker_job)
        refs = [remote.remote(job, limits()) for job in jobs]
        index = {ref: i for i, ref in enumerate(refs)}
        pending, done = list(refs), 0
        while pending:
            ready, pending = ray.wait(pending, num_returns=1)
            done += len(ready)
            if progress:
                progress(done, len(jobs), jobs[index[ready[0]]].describe())
        return list(ray.get(refs))
    finally:
        if started:
            ray.shutdown()


def run_sweep(
    jobs: Sequence[Job], workers: int = 1, ray_address: str | None = None, progress: Progress | None = None
) -> list[dict]:
    """Run the jobs (in this process with ``workers`` 1, in ``workers`` processes, or on the Ray cluster at
    ``ray_address``: "local" starts one on this machine, "auto" joins a running head); records in job order."""
    if workers < 1:
        raise InputError(f"sweep: workers must be >= 1, got {workers}")
    if ray_address is not None:
        return _on_ray(jobs, ray_address, progress)
    if workers == 1:
        return _in_process(jobs, progress)
    return map_in_workers(_job_task, None, jobs, workers, progress, Job.describe)


def sweep_summary(records: Sequence[dict], by: Sequence[str] = ("scene",)) -> list[dict]:
    """``harness.summarise`` rows by ``by`` and costmap mode, plus ``collision_rate`` (over all runs),
    ``median_time_to_goal_s`` and ``mean_min_person_distance_m`` (over successful runs, as summarise's median and
    worst closest approach)."""
    rows = summarise(records, by)
    for row in rows:
        members = [r for r in records if r["social_layer"] == row["social_layer"] and all(r[k] == row[k] for k in by)]
        ok = [r for r in members if r["success"]]
        times = [r["time_to_goal_s"] for r in ok]
        distances = [r["min_person_distance_m"] for r in ok if r["min_person_distance_m"] is not None]
        row["collision_rate"] = sum(r["collisions"] > 0 for r in members) / len(members)
        row["median_time_to_goal_s"] = statistics.median(times) if times else None
        row["mean_min_person_distance_m"] = statistics.fmean(distances) if distances else None
    return rows
