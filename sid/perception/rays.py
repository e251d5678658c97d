"""The paper's ray method (``GroupParams.method`` ``rays`` and ``paper``), all coordinates in the world frame (metres,
REP-103), angles in radians.

The ray method. Per frame: DBSCAN on the people's positions; per cluster, each person with a known facing casts a
ray (a segment of ``ray_length``) from their position along their facing; where two rays cross, the two people
look at a common point. The convex hull of the crossings is the interaction zone (area A, centroid = interest
point), and D is the mean distance of the members to the interest point. While A or D exceed their thresholds, the
member whose removal helps most is dropped; a cluster that ends under both thresholds is a group.

Choices the paper leaves open, decided here:
- People with unknown facing (theta None) count in DBSCAN (they are there, and link neighbours) but cast no ray,
  so they are never members: a ray is the only evidence of taking part in a conversation.
- A member whose ray meets no other member's ray is dropped before the geometry (it contributes no crossing, so
  it could only pass the thresholds by standing close, e.g. someone just behind a group facing away).
- Two people facing each other: their rays are (nearly) anti-parallel and often miss each other (parallel, or
  crossing behind one of them), and where they do cross, at a shallow angle, the crossing lies anywhere between
  the two (on one of them when the other looks straight at them) and follows every degree of facing noise. So
  when each faces the other within ``facing_tolerance`` and their rays are within 20 degrees of anti-parallel, the
  pair meets at the midpoint between them, crossing or not; a steeper crossing is kept (a face-to-face pair both
  turned towards one side looks at a spot beside the line between them).
- The polygon is the convex hull of the crossings (as the authors' code does), vertices counter-clockwise; area
  and centroid by the shoelace formula. When the hull is degenerate (one crossing, coinciding or
  collinear crossings; area below 1e-9 m^2) the area is 0 and the interest point is the mean of the crossings.
- Pruning removes, at each step, the member whose removal minimises max(A / A_thr, D / D_thr); it stops with no
  group when no removal lowers that value or fewer than two members would remain.
- A DBSCAN cluster may hold several conversations side by side (a coffee break), and pruning one big set of
  people member by member then fails. So the crossings of a cluster are first grouped by proximity
  (``meeting_radius``, single linkage); the people whose rays meet at one spot form a candidate, candidates are
  pruned in order of their number of crossings (most first), and a person joins at most one group. With one
  spot (any single conversation) this is exactly the paper's algorithm; ``meeting_radius=math.inf`` forces it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from sid.perception.cluster import dbscan_labels
from sid.perception.group import Group
from sid.perception.zone import PARALLEL, SHALLOW, spread, zone_of

if TYPE_CHECKING:
    from sid.perception.groups import GroupParams

__all__ = ["clustered_groups", "ray_meetings"]

# Relative difference below which two removals' excess values tie (rounding, e.g. after moving the scene).
_TIE = 1e-9


@dataclass(frozen=True)
class _Geometry:
    """Area (m^2), centre (complex x + iy), (K, 2) zone and spread D (m) of a candidate's crossings."""

    area: float
    centre: complex
    zone: np.ndarray
    spread: float

    def excess(self, params: GroupParams) -> float:
        """max(A / A_thr, D / D_thr): <= 1 when both are under their thresholds."""
        area_ratio = self.area / params.area_threshold if params.area_threshold > 0 else (math.inf if self.area else 0)
        return max(area_ratio, self.spread / params.spread_threshold)


def clustered_groups(
    ids: list[int], positions: list[complex], facing: list[complex], params: GroupParams
) -> list[Group]:
    """The ``rays`` and ``paper`` methods' groups: DBSCAN clusters of the people sorted by id (DBSCAN numbers its
    clusters, and the pruning breaks its ties, in the order it is given), each pruned to its groups; members and
    groups then listed in input order."""
    order = sorted(range(len(ids)), key=ids.__getitem__)
    position_array = np.array([positions[i] for i in order], dtype=complex)
    facing_array = np.array([facing[i] for i in order], dtype=complex)
    labels = dbscan_labels(np.column_stack((position_array.real, position_array.imag)), params.eps, params.min_samples)
    has_ray = ~np.isnan(facing_array)
    groups: list[Group] = []
    for label in range(int(labels.max()) + 1):
        cluster = np.flatnonzero((labels == label) & has_ray)
        if len(cluster) >= 2:
            groups.extend(
                _groups_in_cluster(
                    [ids[order[i]] for i in cluster], position_array[cluster], facing_array[cluster], params
                )
            )
    index = {person: k for k, person in enumerate(ids)}
    for group in groups:
        group.members = tuple(sorted(group.members, key=index.__getitem__))
    return sorted(groups, key=lambda group: index[group.members[0]])


@dataclass(frozen=True)
class _Meetings:
    """Pairs of people (indices into the cluster) whose rays meet, and where (complex x + iy)."""

    first: np.ndarray
    second: np.ndarray
    points: np.ndarray


@lru_cache(maxsize=64)
def _pairs(k: int) -> tuple[np.ndarray, np.ndarray]:
    return np.triu_indices(k, 1)


def ray_meetings(
    positions: np.ndarray,
    facing: np.ndarray,
    params: GroupParams,
    pairs: tuple[np.ndarray, np.ndarray] | None = None,
) -> _Meetings:
    """Where the rays of each pair (all pairs unless given, i < j) meet (see the module docstring); positions and
    facings are complex numbers x + iy. Dot and cross products are written out on the real parts: numpy's complex
    products fuse multiply-adds on some CPUs, which would make the last bits depend on the machine and differ from
    ``member_crossings``' Python arithmetic."""
    i, j = _pairs(len(positions)) if pairs is None else pairs
    pi, pj, fi, fj = positions[i], positions[j], facing[i], facing[j]
    d = pj - pi
    dx, dy, fix, fiy, fjx, fjy = d.real, d.imag, fi.real, fi.imag, fj.real, fj.imag
    # Rays p_i + s f_i and p_j + t f_j meet where s f_i - t f_j = d = p_j - p_i: s = cross(d, f_j) / cross(f_i, f_j)
    # and t = cross(d, f_i) / cross(f_i, f_j); the segments meet when both lie in [0, ray_length].
    denom = fix * fjy - fiy * fjx
    half = 0.5 * params.ray_length
    distance = np.abs(d)
    # Face to face: each looks at the other within the tolerance (dot(f, d) >= cos(tol) |d|).
    reach = math.cos(params.facing_tolerance) * distance
    facing_j = dx * fix + dy * fiy >= reach
    facing_i = -(dx * fjx + dy * fjy) >= reach
    face_to_face = facing_j & facing_i & (distance > 0) & (distance <= 4 * half)
    # A denominator next to 0 (facings parallel to within ~1e-300) overflows s and t to inf; such pairs are not
    # crossings (|denom| <= PARALLEL) and take the midpoint, so the inf is never used.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = (dx * fjy - dy * fjx) / denom
        t = (dx * fiy - dy * fix) / denom
        crossing = (np.abs(denom) > PARALLEL) & (np.maximum(np.abs(s - half), np.abs(t - half)) <= half)
        # A face-to-face pair whose rays are nearly anti-parallel meets at its midpoint, whether or not they cross.
        points = np.where(crossing & ~(face_to_face & (np.abs(denom) < SHALLOW)), pi + s * fi, 0.5 * (pi + pj))
    meet = crossing | face_to_face
    return _Meetings(i[meet], j[meet], points[meet])


def _groups_in_cluster(ids: list[int], positions: np.ndarray, facing: np.ndarray, params: GroupParams) -> list[Group]:
    meetings = ray_meetings(positions, facing, params)
    points = meetings.points
    if len(points) == 0:
        return []
    if math.isinf(params.meeting_radius) or np.abs(points[:, None] - points[None, :]).max() <= params.meeting_radius:
        candidates = [np.ones(len(ids), dtype=bool)]  # all crossings within reach of each other: one spot
    else:
        spots = dbscan_labels(np.column_stack((points.real, points.imag)), params.meeting_radius, 1)
        # Candidates in order of their number of crossings, most first (ties: in order of discovery).
        order = sorted(range(int(spots.max()) + 1), key=lambda spot: -np.count_nonzero(spots == spot))
        candidates = []
        for spot in order:
            mask = np.zeros(len(ids), dtype=bool)
            mask[meetings.first[spots == spot]] = True
            mask[meetings.second[spots == spot]] = True
            candidates.append(mask)
    remaining = np.ones(len(ids), dtype=bool)
    groups = []
    for mask in candidates:
        found = _prune(mask & remaining, meetings, positions, ids, params)
        if found is None:
            continue
        members, geometry = found
        groups.append(
            Group(
                members=tuple(ids[i] for i in np.flatnonzero(members)),
                interest_point=(geometry.centre.real, geometry.centre.imag),
                area=geometry.area,
                zone=geometry.zone,
                spread=geometry.spread,
            )
        )
        remaining &= ~members
    return groups


def _active(members: np.ndarray, meetings: _Meetings) -> np.ndarray:
    """Which meetings are between two members."""
    return members[meetings.first] & members[meetings.second]


def _with_meetings(members: np.ndarray, meetings: _Meetings) -> np.ndarray:
    """The members whose ray meets another member's ray."""
    active = _active(members, meetings)
    result = np.zeros_like(members)
    result[meetings.first[active]] = True
    result[meetings.second[active]] = True
    return result


def _geometry(members: np.ndarray, meetings: _Meetings, positions: np.ndarray) -> _Geometry:
    """The zone of the crossings between ``members`` (bool mask)."""
    area, centre, zone = zone_of(meetings.points[_active(members, meetings)].tolist())
    return _Geometry(area, centre, zone, spread(positions[members].tolist(), centre))


def _prune(
    candidates: np.ndarray, meetings: _Meetings, positions: np.ndarray, ids: list[int], params: GroupParams
) -> tuple[np.ndarray, _Geometry] | None:
    """The group left after pruning ``candidates`` (bool mask), with its geometry, or None.

    Removals whose excess ties (within rounding: moving the scene must not change the choice) go to the lowest
    person id, so that neither the input order nor the scene's placement decides between them."""
    members = _with_meetings(candidates, meetings)
    if np.count_nonzero(members) < 2:
        return None
    geometry = _geometry(members, meetings, positions)
    excess = geometry.excess(params)
    while excess > 1.0:
        best: tuple[float, np.ndarray, _Geometry, int] | None = None
        for i in np.flatnonzero(members):
            trial = members.copy()
            trial[i] = False
            trial = _with_meetings(trial, meetings)
            if np.count_nonzero(trial) < 2:
                continue
            trial_geometry = _geometry(trial, meetings, positions)
            trial_excess = trial_geometry.excess(params)
            if best is None or trial_excess < best[0] - _TIE * max(1.0, best[0]):
                best = (trial_excess, trial, trial_geometry, ids[i])
            elif trial_excess <= best[0] + _TIE * max(1.0, best[0]) and ids[i] < best[3]:
                best = (min(trial_excess, best[0]), trial, trial_geometry, ids[i])
        if best is None or best[0] >= excess:
            return None
        excess, members, geometry, _ = best
    return members, geometry
