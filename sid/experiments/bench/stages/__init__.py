"""The stages ``sid bench`` times, each on a fixed, seeded input, and what each corresponds to in the paper.

Every benchmark returns one or more stage records ``{"median_ms", "min_ms", "max_ms", "runs", ...extra}``
keyed by stage name. Extra fields: ``paper_ms`` (the paper's Table 2 figure for the same step, from a Jetson Orin
NX, another machine; docs/benchmarks.md), ``ratio_to`` (the stage this one is compared with:
``sid.experiments.bench.suite`` adds ``ratio`` = this median / that median), and counts or checks that show the
stage did its work.

Each benchmark imports what it times inside its own function, so that a module that fails to import (or an
optional piece missing on a machine) costs only the benchmarks that need it, reported as such, not the run.

Modules: ``core`` (the run's context, the benchmark record, the paper's figures), ``inputs`` (the shared scenes
and frames), one module per part of the system: ``grouping``, ``camera`` (alignment, lifting, rendering),
``networks`` (pose models, the per-frame pipeline), ``navigation`` (costmap, planners), ``tracking`` (tracked
frames, real crowds).
"""

from __future__ import annotations

from sid.experiments.bench.stages.camera import depth_benchmarks, render_benchmarks
from sid.experiments.bench.stages.core import Benchmark, Context, Records, record
from sid.experiments.bench.stages.grouping import grouping_benchmarks
from sid.experiments.bench.stages.inputs import grouping_scene
from sid.experiments.bench.stages.navigation import costmap_benchmarks, planning_benchmarks
from sid.experiments.bench.stages.networks import frame_benchmarks, pose_benchmarks, pose_models, real_rgbd_folders
from sid.experiments.bench.stages.tracking import (
    CROWD_SETS,
    CROWD_SIZES,
    crowd_benchmarks,
    crowd_sets,
    track_benchmarks,
)

__all__ = [
    "CROWD_SETS",
    "CROWD_SIZES",
    "Benchmark",
    "Context",
    "Records",
    "benchmarks",
    "crowd_sets",
    "grouping_scene",
    "pose_models",
    "real_rgbd_folders",
    "record",
]


def benchmarks(ctx: Context) -> list[Benchmark]:
    """Every benchmark of ``sid bench`` in report order: pose benchmarks for the models found under ``ctx.shared``
    and crowd benchmarks for its trajectory sets (a note when there are none), planning benchmarks for every
    registered planner."""
    return [
        *grouping_benchmarks(),
        *depth_benchmarks(),
        *pose_benchmarks(ctx),
        *frame_benchmarks(),
        *costmap_benchmarks(),
        *track_benchmarks(),
        *crowd_benchmarks(ctx),
        *planning_benchmarks(ctx),
        *render_benchmarks(),
    ]
