"""Costmap timing: a full per-frame update of a 20 m x 20 m map at 5 cm with a 720-beam scan and 3 groups.

``bench_costmap_update`` returns medians in milliseconds (for ``sid bench``); run ``python -m costmap.bench`` to
print them. Numbers depend on the machine; nothing here asserts a time.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from costmap.grid import GridSpec
from costmap.layered import LayeredCostmap
from costmap.obstacles import BoxObstacle, CircleObstacle, SegmentObstacle
from costmap.scan import simulate_scan
from sid.groups import Group
from sid.people import Person


def _median_ms(fn: Callable[[], object], repeats: int, warmup: int = 3) -> float:
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter_ns()
        fn()
        times.append(time.perf_counter_ns() - start)
    return float(np.median(times)) / 1e6


def bench_scene(
    size_m: float = 20.0, group_sizes: tuple[int, ...] = (3, 4, 3), shift: float = 0.0
) -> tuple[list, list[Person], list[Group]]:
    """A room with walls, a pillar and a table, and circular groups of ``group_sizes`` people facing their centre.

    ``shift`` moves every person by that many metres along x (to benchmark people who move between frames).
    """
    h = size_m / 2 - 0.5
    obstacles = [
        SegmentObstacle(((-h, -h), (h, -h), (h, h), (-h, h), (-h, -h))),
        SegmentObstacle(((-3.0, 4.0), (6.0, 4.0))),
        CircleObstacle((-4.0, -5.0), 0.3),
        BoxObstacle((5.0, -7.0), (7.0, -6.0)),
    ]
    centres = [(4.0, 0.0), (-5.0, 2.0), (1.0, -6.0)]
    people, groups, pid = [], [], 1
    for (cx, cy), n in zip(centres, group_sizes, strict=False):
        angles = np.linspace(0, 2 * np.pi, n, endpoint=False) + 0.3
        members = []
        for a in angles:
            people.append(Person(pid, cx + shift + 0.7 * np.cos(a), cy + 0.7 * np.sin(a), float(a + np.pi), 1.0))
            members.append(pid)
            pid += 1
        zone = np.array([[cx + shift + 0.15 * np.cos(a), cy + 0.15 * np.sin(a)] for a in angles])
        groups.append(Group(tuple(members), (cx + shift, cy), 0.05, zone, 0.7))
    return obstacles, people, groups


def bench_costmap_update(repeats: int = 50, size_m: float = 20.0, resolution: float = 0.05, beams: int = 720) -> dict:
    """Medians (ms) of a full update and of its parts, on a ``size_m`` square map at ``resolution``.

    update_ms: ``LayeredCostmap.update`` with a new scan, people who moved 5 cm since the last frame and 3 groups
    (LiDAR clear+mark, people clearing, social layer, combination, inflation); update_baseline_ms: the same without
    the social layer; scan_sim_ms: the simulated LiDAR itself (a real robot gets the scan from its driver);
    inflation_opencv_ms / inflation_scipy_ms: the inflation layer alone with each distance transform.
    """
    spec = GridSpec.from_size(resolution, (-size_m / 2, -size_m / 2), (size_m, size_m))
    frames = []
    for shift in (0.0, 0.05):
        obstacles, people, groups = bench_scene(size_m, shift=shift)
        frames.append((people, groups, simulate_scan((0.0, 0.0, 0.0), obstacles, people, beams=beams)))
    obstacles, people, groups = bench_scene(size_m)
    counter = iter(range(10**9))

    def alternate(layered: LayeredCostmap) -> Callable[[], None]:
        def step() -> None:
            people_k, groups_k, scan_k = frames[next(counter) % 2]
            layered.update(people_k, groups_k, scan_k)

        return step

    social, baseline = LayeredCostmap(spec), LayeredCostmap(spec, social=False)
    result = {
        "map_cells": spec.width * spec.height,
        "beams": beams,
        "people": len(people),
        "groups": len(groups),
        "update_ms": _median_ms(alternate(social), repeats),
        "update_baseline_ms": _median_ms(alternate(baseline), repeats),
        "scan_sim_ms": _median_ms(lambda: simulate_scan((0, 0, 0), obstacles, people, beams=beams), repeats),
        "lidar_ms": _median_ms(lambda: social.lidar.apply_scan(frames[0][2]), repeats),
        "social_ms": _median_ms(lambda: social.social.update(people, groups), repeats),
    }
    social.update(*frames[0])
    master = social.master.costs.copy()  # walls and bodies, before inflation is added again below
    for method in ("opencv", "scipy"):
        result[f"inflation_{method}_ms"] = _median_ms(
            lambda m=method: social.inflation.apply(master.copy(), m), repeats
        )
    return result


if __name__ == "__main__":
    for key, value in bench_costmap_update().items():
        print(f"{key:>22}: {value:.3f}" if isinstance(value, float) else f"{key:>22}: {value}")
