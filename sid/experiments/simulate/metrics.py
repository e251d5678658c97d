"""The metrics of a driven run, measured on the trajectory against the people and groups where they truly were at
each step (the groups ``sid.perception.groups.detect_groups`` finds on the exact positions, as in
``sid.experiments.harness``), whatever the robot saw.

Each step's segment (from the robot's position at t to its position at t + dt) is measured with
``sid.experiments.path_metrics`` against the people and groups of time t: length inside any group's interaction zone
(``ospace_intrusion_m``, summed) and whether it crosses the segment between two members (``crosses_group``). The
distance to every person's centre (``min_person_distance_m``: the smallest over the run) is the closest approach
over the step, the robot and each person moving straight from where they were at t to where they are at t + dt
(``sid.experiments.simulate.world.closest_approach``, as the collision check): against the people of time t alone a
walker crossing the robot's segment read nearer than they ever were. ``personal_space_fraction``
means what it means for a planned path (``path_metrics``): the share of samples at most ``SAMPLE_SPACING_M`` apart
along the driven path (every vertex included) closer than ``PERSONAL_DISTANCE_M`` to someone, each sample measured
against the people of its step; steps spent standing still add no path and no samples. Map frame, metres, seconds.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from shapely.geometry import LineString
from shapely.ops import unary_union

from planner.validity import interpolate
from sid.experiments.path_metrics import (
    PERSONAL_DISTANCE_M,
    SAMPLE_SPACING_M,
    crosses_group,
    group_zones,
    min_distance_to_points,
    nearest_distances,
    path_length,
)
from sid.experiments.simulate.loop import RunTrace
from sid.experiments.simulate.world import closest_approach

__all__ = ["run_metrics"]


def run_metrics(trace: RunTrace, straight_m: float) -> dict[str, Any]:
    """The run's record (JSON-ready): outcome, social metrics, replans, planning time and the trajectory.

    ``straight_m``: straight-line distance from start to goal (m), for ``length_ratio``.
    """
    trajectory = np.array(trace.trajectory, dtype=float).reshape(-1, 4)
    xy = trajectory[:, 1:3]
    intrusion, crosses, nearest, personal, samples = 0.0, False, math.inf, 0, 0
    for i, (people, groups) in enumerate(trace.truth):
        segment = xy[i : i + 2]
        positions = np.array([(p.x, p.y) for p in people], dtype=float).reshape(-1, 2)
        if len(segment) == 2 and people:  # the trajectory and trace.truth run in step: the next step's people
            (x0, y0), (x1, y1) = segment.tolist()
            nearest = min(nearest, float(closest_approach((x0, y0), (x1, y1), people, trace.truth[i + 1][0]).min()))
        else:
            nearest = min(nearest, min_distance_to_points(segment, positions))
        if len(segment) == 1:  # the final position: the path's last vertex
            points = segment
        elif path_length(segment) > 0:  # the segment's samples but its end, the next segment's start
            points = interpolate(segment, SAMPLE_SPACING_M)[:-1]
        else:
            points = segment[:0]
        personal += int((nearest_distances(points, positions) < PERSONAL_DISTANCE_M).sum())
        samples += len(points)
        if groups and len(segment) == 2:
            zones = unary_union(group_zones(people, groups))
            intrusion += float(LineString(segment).intersection(zones).length)
            crosses = crosses or crosses_group(segment, people, groups)
    length = path_length(xy)
    return {
        "success": trace.success,
        "reason": trace.reason,
        "collisions": trace.collisions,
        "time_to_goal_s": round(trace.time_s, 3) if trace.success else None,
        "time_s": round(trace.time_s, 3),
        "path_length_m": length,
        "length_ratio": length / straight_m if trace.success and straight_m > 0 else None,
        "min_person_distance_m": nearest if math.isfinite(nearest) else None,
        "ospace_intrusion_m": intrusion,
        "crosses_group": crosses,
        "personal_space_fraction": personal / max(samples, 1),
        "replans": trace.replans,
        "plans": trace.plans,
        "planning_time_s": trace.planning_time_s,
        "trajectory": [[round(v, 4) for v in row] for row in trace.trajectory],
    }
