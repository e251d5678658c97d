"""Conversations the known map allows: nobody talks through a wall (world frame, metres).

The group detector sees people only (``sid.perception.groups``): two people on either side of a thin wall, facing
each other, are a pair to it. Where a scenario's map is known (its obstacles and ``static_map`` file), a group
whose members cannot all see one another past the map's occupied cells is taken apart: the members are split into
the parts that see each other (directly or through a fellow member), and each part's people are grouped again on
their own.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse
import scipy.sparse.csgraph

from costmap.grid import LETHAL, GridSpec
from costmap.layers.static import static_costs
from costmap.mapfile import read_map
from costmap.occupancy import OccupancyGrid
from sid.perception.group import Group
from sid.perception.groups import GroupParams, detect_groups
from sid.perception.people import Person
from sid.scenario.known_map import known_map
from sid.scenario.loader import Scenario

__all__ = ["Walls", "groups_in_sight", "known_walls", "scenario_groups", "scenario_walls"]


@dataclass(frozen=True, eq=False)
class Walls:
    """The occupied (LETHAL) cells of a known map on its grid ``spec`` ((rows, cols) bool), and whether a straight
    line of sight crosses one."""

    spec: GridSpec
    occupied: np.ndarray

    def block(self, a: tuple[float, float], b: tuple[float, float]) -> bool:
        """True when the segment from ``a`` to ``b`` (m) passes through an occupied cell: sampled every half cell,
        the cells of its two ends included."""
        steps = max(1, int(np.ceil(2.0 * np.hypot(b[0] - a[0], b[1] - a[1]) / self.spec.resolution)))
        t = np.linspace(0.0, 1.0, steps + 1)[:, None]
        cells = self.spec.world_to_cell((1.0 - t) * np.asarray(a) + t * np.asarray(b))
        inside = self.spec.in_bounds(cells)
        return bool(self.occupied[cells[inside, 0], cells[inside, 1]].any())


def scenario_walls(scenario: Scenario) -> Walls | None:
    """The scenario's known map (declared obstacles and ``static_map`` file) as ``Walls``; None without either."""
    if not scenario.obstacles and scenario.static_map is None:
        return None
    static = None if scenario.static_map is None else read_map(scenario.static_map)
    return known_walls(scenario, known_map(scenario.obstacles, scenario.grid, static))


def known_walls(scenario: Scenario, known: OccupancyGrid) -> Walls:
    """``Walls`` of ``known``, the scenario's known map (``sid.scenario.known_map``), read as the static layer reads
    it with unknown space free."""
    return Walls(scenario.grid, static_costs(known, scenario.grid, track_unknown_space=False) == LETHAL)


def groups_in_sight(
    people: Sequence[Person], groups: Sequence[Group], walls: Walls | None, params: GroupParams
) -> list[Group]:
    """``groups`` (detected on ``people``), each whose members do not all see one another past ``walls`` replaced
    by the groups of its parts (``detect_groups`` on each part's people alone). None: ``groups`` as they are."""
    if walls is None:
        return list(groups)
    by_id = {p.id: p for p in people}
    out: list[Group] = []
    for group in groups:
        members = [by_id[i] for i in group.members]
        sees = np.zeros((len(members), len(members)), dtype=bool)
        for i in range(len(members)):
            for j in range(i + 1, len(members)):
                a, b = members[i], members[j]
                sees[i, j] = not walls.block((a.x, a.y), (b.x, b.y))
        count, labels = scipy.sparse.csgraph.connected_components(scipy.sparse.csr_matrix(sees), directed=False)
        if count == 1:
            out.append(group)
            continue
        for part in range(count):
            apart = [m for m, label in zip(members, labels.tolist(), strict=True) if label == part]
            out.extend(detect_groups(apart, params))
    order = {p.id: k for k, p in enumerate(people)}
    return sorted(out, key=lambda g: order[g.members[0]])  # as detect_groups: by their first member


def scenario_groups(
    scenario: Scenario, people: Sequence[Person] | None = None, walls: Walls | None = None
) -> list[Group]:
    """The groups of ``people`` (default the scenario's) that its known map allows: ``detect_groups`` with the
    scenario's parameters, then ``groups_in_sight`` past ``walls`` (default the scenario's, ``scenario_walls``)."""
    people = scenario.people if people is None else people
    walls = scenario_walls(scenario) if walls is None else walls
    return groups_in_sight(people, detect_groups(people, scenario.group_params), walls, scenario.group_params)
