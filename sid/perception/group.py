"""The group record: who is with whom, the interest point and the interaction zone, on the ground plane.

Same frame as the members' ``Person`` records (``base_footprint`` or ``map``, metres). Filled by the detectors of
``sid.perception.groups``; read by the costmap, the planner's metrics and the trackers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Group", "group_json"]


@dataclass
class Group:
    """An interacting group.

    members: person ids; interest_point: (x, y) of the o-space centre; area: interaction-zone area (m^2);
    zone: (K, 2) polygon of ray crossings, counter-clockwise (one vertex for a pair); spread: D, the mean
    member distance to the interest point (m).
    """

    members: tuple[int, ...]
    interest_point: tuple[float, float]
    area: float
    zone: np.ndarray
    spread: float


def group_json(group: Group) -> dict[str, Any]:
    """A group as plain JSON (world frame, m, m^2; the zone's vertices to 0.1 mm): the format of ``sid groups``,
    ``sid detect`` and the ROS node's group messages."""
    return {
        "members": [int(m) for m in group.members],
        "interest_point": [float(v) for v in group.interest_point],
        "area": float(group.area),
        "spread": float(group.spread),
        "zone": np.asarray(group.zone, dtype=float).round(4).tolist(),
    }
