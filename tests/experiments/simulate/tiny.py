"""Small simulation worlds for the tests: a 5 x 4 m corridor, a fast robot, short time limits."""

from __future__ import annotations

import copy
from typing import Any

from sid.experiments.simulate.world import SimWorld, world_from_dict

PAIR = [{"id": 1, "x": 2.0, "y": 0.6, "theta": -1.5708}, {"id": 2, "x": 2.0, "y": -0.6, "theta": 1.5708}]
TINY: dict[str, Any] = {
    "name": "tiny",
    "simulation": {"max_speed": 1.0, "time_limit_s": 10.0},
    "map": {"resolution": 0.05, "origin": [-0.5, -2.0], "size": [5.0, 4.0]},
    "obstacles": [
        {"type": "segment", "points": [[-0.5, 1.8], [4.5, 1.8]]},
        {"type": "segment", "points": [[-0.5, -1.8], [4.5, -1.8]]},
    ],
    "people": PAIR,
    "robot": {"start": [0.0, 0.0, 0.0], "goal": [4.0, 0.0, 0.0], "radius": 0.25},
}


def tiny_world(**changes: Any) -> SimWorld:
    """The tiny world with top-level fields replaced (``simulation`` is merged)."""
    data = copy.deepcopy(TINY)
    simulation = changes.pop("simulation", {})
    data.update(changes)
    data["simulation"] = data["simulation"] | simulation
    return world_from_dict(data)
