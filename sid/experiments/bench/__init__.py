"""``sid bench``: time the stages that matter side by side in one run and keep a comparable report.

>>> from sid.experiments.bench import Context, FULL, benchmarks, run_suite, select
>>> ctx = Context(FULL, shared=Path("../shared"), plan_runs=5)
>>> result = run_suite(select(benchmarks(ctx), "group,group_baseline"), ctx)
>>> result.stages["group_baseline/4"]["ratio"]   # the authors' approach / ours, same scene, same run

Modules: ``runner`` (timing harness), ``stages`` (what is timed, on which input, and the paper's figure for it),
``baseline`` (the paper authors' grouping approach, re-implemented as a timing baseline only), ``crowd_scene``
(real pedestrian trajectories stacked into a crowd of N for ``crowd/N``), ``suite`` (selection, progress, ratios),
``report`` (bench.json / bench.md, comparison of two reports).
"""

from sid.experiments.bench.baseline import BaselineGroup, BaselineParams, baseline_groups
from sid.experiments.bench.report import format_comparison, load_report, machine_info, markdown, write_report
from sid.experiments.bench.runner import FULL, QUICK, RunSettings, Stats, measure, measure_parts
from sid.experiments.bench.stages import Benchmark, Context, benchmarks, grouping_scene
from sid.experiments.bench.suite import SuiteResult, run_suite, select

__all__ = [
    "FULL",
    "QUICK",
    "BaselineGroup",
    "BaselineParams",
    "Benchmark",
    "Context",
    "RunSettings",
    "Stats",
    "SuiteResult",
    "baseline_groups",
    "benchmarks",
    "format_comparison",
    "grouping_scene",
    "load_report",
    "machine_info",
    "markdown",
    "measure",
    "measure_parts",
    "run_suite",
    "select",
    "write_report",
]
