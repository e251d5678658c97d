"""Conversational groups (the paper's Algorithm 1): records and detection.

All coordinates are in the world frame (metres, REP-103, see ``sid.people``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class GroupParams:
    """Parameters of the group detector (metres, square metres)."""

    eps: float = 2.0
    min_samples: int = 2
    area_threshold: float = 1.5
    spread_threshold: float = 1.5
    ray_length: float = 3.0


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
