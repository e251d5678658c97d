"""Inputs and a test layer shared by the costmap tests: moving people with scans, a conversation of three, a layer
of unknown cells (world frame, metres)."""

from __future__ import annotations

import numpy as np

from costmap.grid import NO_INFORMATION, GridSpec, Window
from costmap.layer import Layer, LayerInputs
from costmap.layers.obstacle import SCAN
from costmap.layers.social import GROUPS, PEOPLE
from sid.perception.group import Group
from sid.perception.groups import detect_groups
from sid.perception.people import Person
from sid.scenario.lidar import simulate_scan
from sid.scenario.obstacles import CircleObstacle, SegmentObstacle

WALLS = [SegmentObstacle(((-1.0, 2.5), (9.0, 2.5))), CircleObstacle((6.0, -2.0), 0.3)]


def frames() -> list[LayerInputs]:
    """People who walk, leave and arrive, with a scan in some frames only (from a robot that moves)."""
    people = [Person(1, 4.0, 0.0, np.pi), Person(2, 4.6, 0.5, -2.0), Person(3, 4.6, -0.5, 2.0), Person(4, 2.0, -2.0)]
    out = []
    for step in range(6):
        moved = [Person(p.id, p.x + 0.2 * step, p.y - 0.1 * step, p.theta) for p in people[: 4 - step // 3]]
        scan = None if step in (2, 4) else simulate_scan((0.3 * step, 0.0, 0.0), WALLS, moved, beams=360)
        out.append(LayerInputs({PEOPLE: moved, GROUPS: detect_groups(moved), SCAN: scan}))
    return out


def triad() -> tuple[list[Person], Group]:
    """Three people 0.6 m around (4, 0), facing the centre, and their group (o-space = small triangle)."""
    angles = np.deg2rad([90, 210, 330])
    people = [Person(i + 1, 4 + 0.6 * np.cos(a), 0.6 * np.sin(a), float(a + np.pi), 1.0) for i, a in enumerate(angles)]
    zone = np.array([[4.0, 0.2], [3.83, -0.1], [4.17, -0.1]])
    return people, Group((1, 2, 3), (4.0, 0.0), 0.05, zone, 0.6)


class Unknown(Layer):
    """A 1 m square of unknown cells around (2, 2), with the combination method it is given."""

    name = "unknown"

    def __init__(self, spec: GridSpec, combination: str) -> None:
        self.combination = combination
        super().__init__(spec)

    def update(self, inputs: LayerInputs, changed: Window | None) -> Window | None:
        window = self.spec.window((1.5, 1.5), (2.45, 2.45))
        assert window is not None
        self.costs[window.slices] = NO_INFORMATION
        return window
