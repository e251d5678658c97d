"""One simulated run (``sid simulate SCENE``): the closed loop, its metrics, and its files.

``run_record`` gives the JSON-ready record of ``run.json``: the scene, the options that made the run (replaying
them gives the same run), the outcome and metrics of ``sid.experiments.simulate.metrics.run_metrics`` and the
trajectory. ``write_run`` also writes ``run.mp4`` (and on request ``run.gif``, and ``run.png``: the picture of one
step).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from sid.documents import InputWarning
from sid.experiments.progress import Progress
from sid.experiments.reproduce import write_json
from sid.experiments.simulate.loop import Observer, RunOptions, StepView, simulate
from sid.experiments.simulate.metrics import run_metrics
from sid.experiments.simulate.video import VideoWriter, frame_picture
from sid.experiments.simulate.world import SimWorld

__all__ = ["options_record", "run_record", "write_run"]


def options_record(options: RunOptions) -> dict[str, Any]:
    """The options as JSON-ready fields (the model as a path string; ``social`` as the record's ``social_layer``)."""
    record = asdict(options)
    record.pop("social")  # the record's ``social_layer``
    record["model"] = None if options.model is None else str(options.model)
    return record


def run_record(
    world: SimWorld, options: RunOptions, observer: Observer | None = None, color: bool = False
) -> dict[str, Any]:
    """Simulate once and return the run's record (see the module docstring); ``color``: see ``simulate``."""
    trace = simulate(world, options, observer, color)
    (x0, y0, _), (x1, y1, _) = world.scenario.robot.start, world.scenario.robot.goal
    metrics = run_metrics(trace, math.hypot(x1 - x0, y1 - y0))
    trajectory = metrics.pop("trajectory")
    return {"scene": world.scenario.name, "social_layer": options.social, **options_record(options), **metrics,
            "trajectory": trajectory}  # fmt: skip


def write_run(
    world: SimWorld,
    options: RunOptions,
    out_dir: Path | None,
    gif: bool = False,
    progress: Progress | None = None,
    still_s: float | None = None,
) -> dict[str, Any]:
    """Run once; with ``out_dir``, write ``run.json`` and ``run.mp4`` (and ``run.gif``; with ``still_s``, ``run.png``:
    the picture of the first step at or after ``still_s`` seconds, or of the last step, with an InputWarning when the
    run ended before ``still_s``) there. Returns the record. ``progress(step, steps at the time limit, what)`` after
    each step, and ``progress(steps run, steps run, reason)`` at the end (the goal may be reached early)."""
    settings = world.settings
    total = int(math.ceil(settings.time_limit_s * settings.rate_hz))
    driven: list[tuple[float, float]] = []
    writer = None
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
        writer = VideoWriter(out_dir / "run.mp4", settings.rate_hz, out_dir / "run.gif" if gif else None)
    still: list = []  # [t, picture] of the step run.png shows
    mode = "with" if options.social else "without"
    label = f"{world.scenario.name}, {mode} the social layer, seed {options.seed}"

    last = 0  # the last step run

    def observe(view: StepView) -> None:
        nonlocal last
        driven.append((view.robot.x, view.robot.y))
        step = last = int(round(view.t * settings.rate_hz))
        if progress is not None:
            progress(step, total, f"t = {view.t:4.1f} s")
        if writer is not None:
            title = f"{label}: t = {view.t:5.1f} s, v = {view.robot.v:.2f} m/s"
            picture = frame_picture(view, world, np.array(driven), title)
            writer.add(picture)
            if still_s is not None and (not still or still[0] < still_s - 0.5 / settings.rate_hz):
                still[:] = [view.t, picture]

    try:
        record = run_record(world, options, observe, color=writer is not None)
    finally:
        if writer is not None:
            writer.close()
    if progress is not None:  # the run's own end: the goal may be reached before the time limit
        progress(last, last, record["reason"])
    if out_dir is not None:
        write_json(out_dir / "run.json", record)
        if still and not cv2.imwrite(str(out_dir / "run.png"), still[1]):
            raise OSError(f"could not write {out_dir / 'run.png'}")
        if still and still_s is not None and still[0] < still_s - 0.5 / settings.rate_hz:
            message = (
                f"run.png: the run's last step is at t = {still[0]:.1f} s, before {still_s:g} s: it shows that step"
            )
            warnings.warn(InputWarning(message), stacklevel=2)
    return record
