"""The costmap benchmark's scene: a 20 m room with walls, a pillar, a table and circular groups (world frame, m)."""

from __future__ import annotations

import numpy as np

from sid.perception.group import Group
from sid.perception.people import Person
from sid.scenario.obstacles import BoxObstacle, CircleObstacle, Obstacle, SegmentObstacle

__all__ = ["bench_scene"]


def bench_scene(
    size_m: float = 20.0, group_sizes: tuple[int, ...] = (3, 4, 3), shift: float = 0.0
) -> tuple[list[Obstacle], list[Person], list[Group]]:
    """A room with walls, a pillar and a table, and circular groups of ``group_sizes`` people facing their centre.

    ``shift`` moves every person by that many metres along x (to benchmark people who move between frames).
    """
    h = size_m / 2 - 0.5
    obstacles: list[Obstacle] = [
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
