"""``costmap/*`` and ``plan/*``: the layered costmap's updates and inflation on the bench scene, and each planner
and the smoother on the demo scenario."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from sid.experiments.bench.runner import Stats, measure
from sid.experiments.bench.stages.core import (
    Benchmark,
    Context,
    Records,
    record,
)

if TYPE_CHECKING:
    from sid.experiments.harness import Task

__all__ = ["costmap_benchmarks", "planning_benchmarks"]


def _costmap_setup(ctx: Context) -> dict[str, Any]:
    """``sid.experiments.bench.scenes``' scene: a 20 m x 20 m map at 5 cm (400 x 400), a 720-beam scan, 3 groups of
    3-4 people,
    as two frames in which everyone moved 5 cm."""

    def build() -> dict[str, Any]:
        from costmap.grid import GridSpec
        from costmap.layers.obstacle import SCAN
        from costmap.layers.social import GROUPS, PEOPLE
        from sid.experiments.bench.scenes import bench_scene
        from sid.scenario.lidar import simulate_scan

        spec = GridSpec.from_size(0.05, (-10.0, -10.0), (20.0, 20.0))
        frames = []
        for shift in (0.0, 0.05):
            obstacles, people, groups = bench_scene(20.0, shift=shift)
            frames.append(
                {PEOPLE: people, GROUPS: groups, SCAN: simulate_scan((0.0, 0.0, 0.0), obstacles, people, beams=720)}
            )
        return {"spec": spec, "frames": frames}

    return ctx.cached("costmap", build)


def _bench_costmap_update(social: bool) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from costmap.layer import LayerInputs
        from costmap.layers.social import GROUPS, PEOPLE
        from costmap.plugins import CostmapParams, layered_costmap

        setup = _costmap_setup(ctx)
        params = CostmapParams() if social else CostmapParams().without("social")
        layered = layered_costmap(setup["spec"], params)
        frames, counter = setup["frames"], iter(range(10**9))
        stats = measure(lambda: layered.update(LayerInputs(frames[next(counter) % 2])), ctx.settings)
        name = "costmap/update" if social else "costmap/update_no_social"
        people, groups = frames[0][PEOPLE], frames[0][GROUPS]
        return {name: record(stats, cells=setup["spec"].width * setup["spec"].height, beams=720,
                             people=len(people), groups=len(groups))}  # fmt: skip

    return run


def _bench_costmap_large(ctx: Context) -> Records:
    """An 80 m x 80 m map at 5 cm (1600 x 1600): one scan builds it, then only the 3 groups move (5 cm a frame)."""
    from costmap.grid import GridSpec
    from costmap.layer import LayerInputs
    from costmap.layers.obstacle import SCAN
    from costmap.layers.social import GROUPS, PEOPLE
    from costmap.plugins import CostmapParams, layered_costmap
    from sid.experiments.bench.scenes import bench_scene
    from sid.scenario.lidar import simulate_scan

    spec = GridSpec.from_size(0.05, (-40.0, -40.0), (80.0, 80.0))
    obstacles, people, groups = bench_scene(80.0)
    layered = layered_costmap(spec, CostmapParams())
    layered.update(
        LayerInputs(
            {PEOPLE: people, GROUPS: groups, SCAN: simulate_scan((0.0, 0.0, 0.0), obstacles, people, beams=720)}
        )
    )
    moved = []
    for shift in (0.05, 0.0):
        _, moved_people, moved_groups = bench_scene(80.0, shift=shift)
        moved.append(LayerInputs({PEOPLE: moved_people, GROUPS: moved_groups}))
    counter = iter(range(10**9))
    stats = measure(lambda: layered.update(moved[next(counter) % 2]), ctx.settings)
    window = layered.update(moved[0])
    cells = 0 if window is None else (window.row1 - window.row0) * (window.col1 - window.col0)
    return {"costmap/update_1600": record(stats, cells=spec.width * spec.height, updated_cells=cells,
                                          people=len(people), groups=len(groups), target_ms=5.0)}  # fmt: skip


def _bench_inflation(ctx: Context) -> Records:
    from costmap.layer import LayerInputs
    from costmap.layers.inflation import InflationLayer, InflationParams
    from costmap.plugins import layered_costmap

    setup = _costmap_setup(ctx)
    spec = setup["spec"]
    layered = layered_costmap(spec)
    layered.update(LayerInputs(setup["frames"][0]))
    master = layered.master.costs.copy()  # walls and bodies (and their inflation, which does not change the result)
    work = master.copy()

    def inflate() -> None:
        # A new layer each call: every lethal cell is new to it, so the whole map is inflated (a layer only
        # recomputes around lethal cells that changed). write() works in place; the 160 kB copy is part of the
        # timing (docs/benchmarks.md).
        np.copyto(work, master)
        InflationLayer(spec, InflationParams(), inscribed_radius=0.25).write(work, spec.whole)

    stats = measure(inflate, ctx.settings)
    return {"costmap/inflation": record(stats, cells=master.size, method="opencv")}


def _planning_task(ctx: Context) -> Task:
    """``sid.experiments.planner_bench.planner_task``, built once per run."""
    from sid.experiments.planner_bench import planner_task

    return ctx.cached("planning", planner_task)


def _bench_plan(planner: str) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from planner.facade import plan
        from sid.experiments.planner_bench import TARGET_BUDGET_S, bench_planner, meets_target

        task = _planning_task(ctx)
        if planner == "grid":  # deterministic: timed like any other stage
            stats = measure(lambda: plan(task.problems["with"], "grid"), ctx.settings)
            return {"plan/grid": record(stats, cost_ratio=1.0, success_rate=1.0)}
        runs, row = bench_planner(task, planner, ctx.plan_runs)
        return {
            f"plan/{planner}": record(
                Stats.of([run.result.planning_time_s * 1e3 for run in runs]),
                budget_s=TARGET_BUDGET_S,
                success_rate=row["success_rate"],
                cost_ratio=row["median_cost_ratio"],
                worst_cost_ratio=row["worst_cost_ratio"],
                meets_target=meets_target(row),
            )
        }

    return run


def _bench_smooth(ctx: Context) -> Records:
    """``planner.smoothing.smooth`` alone on the demo task's BIT* path (seed 1, capped, so the input is fixed)."""
    from planner.facade import plan
    from planner.problem import CostField
    from planner.smoothing import smooth

    problem = _planning_task(ctx).problems["with"]
    raw = plan(problem, "bitstar", time_limit=30.0, seed=1, max_iterations=2000, simplify=False).path
    field = CostField(problem)
    stats = measure(lambda: smooth(field, raw), ctx.settings)
    return {"plan/smooth": record(stats, vertices=len(raw), raw_cost=field.path_cost(raw),
                                  cost=field.path_cost(smooth(field, raw)), target_ms=10.0)}  # fmt: skip


def costmap_benchmarks() -> list[Benchmark]:
    """The costmap updates with and without the social layer, the large map, the inflation alone."""
    return [
        Benchmark("costmap/update", "LayeredCostmap.update, 400x400, 720 beams, 3 groups", _bench_costmap_update(True)),
        Benchmark("costmap/update_no_social", "the same without the social layer", _bench_costmap_update(False)),
        Benchmark("costmap/update_1600", "LayeredCostmap.update, 1600x1600, 3 moving groups", _bench_costmap_large),
        Benchmark("costmap/inflation", "InflationLayer.write alone, whole 400x400 map", _bench_inflation),
    ]


def planning_benchmarks(ctx: Context) -> list[Benchmark]:
    """Every registered planner, then the smoother (a note instead when the planner cannot be imported)."""
    try:
        from planner.facade import PLANNERS as planners
    except ImportError as exc:  # OMPL missing: the rest of the suite still runs
        ctx.note(f"planning benchmarks skipped: the planner cannot be imported ({exc})")
        return []
    items = [Benchmark(f"plan/{p}", f"planner {p} on the demo scenario", _bench_plan(p)) for p in planners]
    if planners:
        items.append(Benchmark("plan/smooth", "planner.smoothing.smooth on a BIT* path", _bench_smooth))
    return items
