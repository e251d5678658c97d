"""``group*/N`` and ``dbscan*/N``: the group detector's methods, groups from positions alone, the authors' approach
and DBSCAN on ``grouping_scene(N)``, one native thread each."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

import numpy as np

from sid.experiments.bench.baseline import BaselineGroup, baseline_groups
from sid.experiments.bench.runner import RunSettings, Stats, measure
from sid.experiments.bench.stages.core import (
    PAPER_GROUP_MS,
    Benchmark,
    Context,
    Records,
    record,
)
from sid.experiments.bench.stages.inputs import grouping_scene
from sid.perception.people import Person

if TYPE_CHECKING:
    from sid.perception.group import Group

__all__ = [
    "DBSCAN_SIZES",
    "GROUPING_THREADS",
    "GROUP_SIZES",
    "PAPER_GROUP_MAX",
    "POSITIONS_ONLY_REACH",
    "grouping_benchmarks",
]

GROUP_SIZES = (2, 3, 4, 6, 20, 100)
# The ray methods above this many people: the authors' approach and sid's `paper` method prune one crowd member by
# member (minutes at 100 people), so their rows stop here.
PAPER_GROUP_MAX = 20
DBSCAN_SIZES = (4, 20)
POSITIONS_ONLY_REACH = 1.0
"""``GroupParams.positions_only_reach`` of the ``group_positions_only/N`` rows: the value docs/groups.md sets for a
detector of positions only."""

# The grouping stages run with native thread pools (OpenMP, BLAS) limited to one thread: the work is tiny, and
# scikit-learn's OpenMP pool (DBSCAN's brute-force neighbour search on small inputs) is many times slower while
# other processes keep the cores busy (docs/benchmarks.md, "Grouping threads"); one thread is how such a step runs
# next to a camera driver and a planner. threadpoolctl is a dependency of scikit-learn, not an extra one.
GROUPING_THREADS = 1


def _measure_one_thread(fn: Callable[[], object], settings: RunSettings) -> Stats:
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=GROUPING_THREADS):
        return measure(fn, settings)


def _member_sets(groups: Iterable[Group | BaselineGroup]) -> set[tuple[int, ...]]:
    return {tuple(sorted(g.members)) for g in groups}


def _bench_group(n: int, method: str | None = None) -> Callable[[Context], Records]:
    """``group/N``: the default detector; ``group_METHOD/N``: another method, with its ratio to the default;
    ``group_positions_only/N``: the default's scene without facings, groups from positions alone turned on
    (``POSITIONS_ONLY``)."""

    def run(ctx: Context) -> Records:
        from dataclasses import replace

        from sid.perception.groups import GroupParams, detect_groups

        people = grouping_scene(n)
        if method is None:
            params = GroupParams()
        elif method == "positions_only":
            params = GroupParams(positions_only_reach=POSITIONS_ONLY_REACH)
            people = [replace(p, theta=None) for p in people]
        else:
            params = GroupParams(method=method)
        stats = _measure_one_thread(lambda: detect_groups(people, params), ctx.settings)
        found = detect_groups(people, params)
        name = f"group/{n}" if method is None else f"group_{method}/{n}"
        extra = {} if method is None else {"ratio_to": f"group/{n}"}
        return {
            name: record(
                stats,
                groups=len(found),
                circles_found=_circles_found(found, n),
                threads=GROUPING_THREADS,
                paper_ms=PAPER_GROUP_MS.get(n),
                **extra,
            )
        }

    return run


def _circles_found(groups: Iterable[Group | BaselineGroup], n: int) -> int:
    """How many of the conversation circles of ``grouping_scene(n)`` came out exactly."""
    people = grouping_scene(n)
    circles = {tuple(p.id for p in people if _circle_of(p, n) == k) for k in {_circle_of(p, n) for p in people}}
    return len(circles & _member_sets(groups))


def _circle_of(person: Person, n: int) -> int:
    """The circle index of a person of ``grouping_scene(n)`` (ids run circle by circle, 4 per circle above 6)."""
    return 0 if n <= 6 else person.id // 4


def _bench_baseline(n: int) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from sid.perception.groups import detect_groups

        people = grouping_scene(n)
        stats = _measure_one_thread(lambda: baseline_groups(people), ctx.settings)
        found = baseline_groups(people)
        same = _member_sets(found) == _member_sets(detect_groups(people))
        return {
            f"group_baseline/{n}": record(
                stats,
                groups=len(found),
                circles_found=_circles_found(found, n),
                same_groups=same,
                threads=GROUPING_THREADS,
                ratio_to=f"group/{n}",
                paper_ms=PAPER_GROUP_MS.get(n),
            )
        }

    return run


def _dbscan_points(n: int) -> np.ndarray:
    return np.array([[p.x, p.y] for p in grouping_scene(n)])


def _bench_dbscan(n: int) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from sid.perception.cluster import dbscan_labels
        from sid.perception.groups import GroupParams

        params, points = GroupParams(), _dbscan_points(n)
        stats = _measure_one_thread(lambda: dbscan_labels(points, params.eps, params.min_samples), ctx.settings)
        return {f"dbscan/{n}": record(stats, eps=params.eps, threads=GROUPING_THREADS)}

    return run


def _bench_dbscan_sklearn(n: int) -> Callable[[Context], Records]:
    def run(ctx: Context) -> Records:
        from sklearn.cluster import DBSCAN

        from sid.perception.cluster import dbscan_labels
        from sid.perception.groups import GroupParams

        params, points = GroupParams(), _dbscan_points(n)

        def fit() -> np.ndarray:
            return DBSCAN(eps=params.eps, min_samples=params.min_samples).fit_predict(points)

        same = bool(np.array_equal(fit(), dbscan_labels(points, params.eps, params.min_samples)))
        stats = _measure_one_thread(fit, ctx.settings)
        return {
            f"dbscan_sklearn/{n}": record(
                stats, eps=params.eps, same_labels=same, threads=GROUPING_THREADS, ratio_to=f"dbscan/{n}"
            )
        }

    return run


# The other methods beside the default, each with its rows' description and the largest scene it runs on.
_COMPARED_METHODS = (
    ("gcff", "method gcff (graph cuts, the literature's reference)", max(GROUP_SIZES)),
    ("rays", "method rays", max(GROUP_SIZES)),
    ("paper", "method paper (Algorithm 1)", PAPER_GROUP_MAX),
    ("positions_only", "the scene without facings, groups from positions alone", max(GROUP_SIZES)),
)


def grouping_benchmarks() -> list[Benchmark]:
    """The grouping stages in report order: the default on every size, each other method and the authors' approach
    beside it (with its ratio to the default), then DBSCAN."""
    items = [
        Benchmark(f"group/{n}", f"sid.perception.groups.detect_groups (default: ospace), {n} people", _bench_group(n))
        for n in GROUP_SIZES
    ]
    for method, what, largest in _COMPARED_METHODS:
        items += [
            Benchmark(
                f"group_{method}/{n}", f"detect_groups, {what}, {n} people", _bench_group(n, method), (f"group/{n}",)
            )
            for n in GROUP_SIZES
            if n <= largest
        ]
    items += [
        Benchmark(
            f"group_baseline/{n}",
            f"authors' approach (sid.experiments.bench.baseline), {n} people",
            _bench_baseline(n),
            (f"group/{n}",),
        )
        for n in GROUP_SIZES
        if n <= PAPER_GROUP_MAX
    ]
    for n in DBSCAN_SIZES:
        items.append(Benchmark(f"dbscan/{n}", f"sid.perception.cluster.dbscan_labels, {n} points", _bench_dbscan(n)))
        items.append(
            Benchmark(
                f"dbscan_sklearn/{n}", f"sklearn DBSCAN, {n} points", _bench_dbscan_sklearn(n), needs=(f"dbscan/{n}",)
            )  # fmt: skip
        )
    return items
