"""BASELINE ONLY: the paper authors' published grouping approach, re-implemented to time it against ours.

Not used by the pipeline. ``sid bench`` times it side by side with ``sid.perception.groups.detect_groups`` and checks
that both find the same groups where their logic agrees. Written from the description of the authors' public ROS 2 node
(its source: docs/benchmarks.md) and the paper's Algorithm 1, with the same building blocks they use:

- scikit-learn ``DBSCAN(eps=3.0, min_samples=2)`` fitted on every call, on the features (x, y, yaw) of each person
  (metres and radians in one space, as their node does);
- every DBSCAN label is processed as a cluster, noise (-1) included, as their node does;
- per cluster, each person is a shapely ``LineString`` 20 m long from their position along their facing; every
  pair's ``intersection`` that is a ``Point`` is a crossing (anti-parallel, collinear rays overlap in a segment and
  count for nothing);
- one crossing: area 0, interest point = the crossing; more: the convex hull of the crossings, area and centroid
  from shapely; a cluster is a group when the area is below 0.5 m^2 and the mean member distance D to the
  interest point is below 3.0 m (strict inequalities, as theirs).

Where the description leaves a gap or their node would fail, this module decides (and says so):

- Two crossings: their node builds ``Polygon(crossings)``, which shapely 2 refuses for two points; here the hull
  of two points is the segment between them (area 0, centroid its midpoint).
- Pruning (``prune=True``, the paper's Algorithm 1; their public node has no pruning): while a cluster of more
  than two members fails, every single removal is evaluated from scratch with the same shapely steps, and the one
  that passes (or else the one with the smallest area, then D) is kept; a cluster that shrinks to two members and still
  fails is no group.
- People with an unknown facing (theta None) cannot cast a ray: they are left out before DBSCAN.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from shapely.geometry import LineString, MultiPoint, Point
from sklearn.cluster import DBSCAN

from sid.errors import InputError
from sid.perception.people import Person

__all__ = ["BaselineGroup", "BaselineParams", "baseline_groups"]


@dataclass(frozen=True)
class BaselineParams:
    """The authors' settings (metres, square metres): DBSCAN eps / min_samples on (x, y, yaw), ray length, area
    and mean-distance thresholds; ``prune`` adds the paper's pruning loop (see the module docstring)."""

    eps: float = 3.0
    min_samples: int = 2
    ray_length: float = 20.0
    area_threshold: float = 0.5
    spread_threshold: float = 3.0
    prune: bool = True


@dataclass(frozen=True)
class BaselineGroup:
    """A group found by the baseline: member ids, interest point (x, y) in the world frame, area (m^2) of the
    crossings' hull and D, the mean member distance to the interest point (m)."""

    members: tuple[int, ...]
    interest_point: tuple[float, float]
    area: float
    spread: float


@dataclass(frozen=True)
class _Evaluation:
    passes: bool
    centre: tuple[float, float] | None
    area: float
    spread: float


def baseline_groups(people: Sequence[Person], params: BaselineParams = BaselineParams()) -> list[BaselineGroup]:
    """Groups among ``people`` (world frame) by the authors' approach, in order of DBSCAN label (noise first).

    Raises ValueError naming the person for a non-finite position or facing.
    """
    known = [p for p in people if p.theta is not None]
    for person in known:
        if not all(math.isfinite(v) for v in (person.x, person.y, _facing(person))):
            raise InputError(
                f"baseline: person {person.id} has a non-finite pose ({person.x}, {person.y}, {person.theta})"
            )
    if len(known) < 2:
        return []
    features = np.array([[p.x, p.y, p.theta] for p in known])
    labels = DBSCAN(eps=params.eps, min_samples=params.min_samples).fit_predict(features)
    groups = []
    for label in sorted(set(labels.tolist())):
        cluster = [known[i] for i in np.flatnonzero(labels == label)]
        found = _detect(cluster, params)
        if found is not None:
            groups.append(found)
    return groups


def _facing(person: Person) -> float:
    """The facing (rad) of a person the baseline kept: people with theta None are left out before DBSCAN."""
    if person.theta is None:
        raise InputError(f"baseline: person {person.id} has no facing (theta None) to cast a ray along")
    return person.theta


def _ray(person: Person, length: float) -> LineString:
    """``length`` metres from the person's position along their facing."""
    theta = _facing(person)
    return LineString(
        [(person.x, person.y), (person.x + length * math.cos(theta), person.y + length * math.sin(theta))]
    )


def _detect(cluster: list[Person], params: BaselineParams) -> BaselineGroup | None:
    members = cluster
    evaluation = _evaluate(members, params)
    while not evaluation.passes:
        if not params.prune or len(members) <= 2:
            return None
        remainders = ([m for m in members if m is not removed] for removed in members)
        scored = [(_evaluate(rest, params), rest) for rest in remainders]
        evaluation, members = min(scored, key=lambda t: (not t[0].passes, t[0].area, t[0].spread))
        if evaluation.centre is None:  # no removal leaves a single crossing
            return None
    assert evaluation.centre is not None
    return BaselineGroup(tuple(p.id for p in members), evaluation.centre, evaluation.area, evaluation.spread)


def _evaluate(members: list[Person], params: BaselineParams) -> _Evaluation:
    """Area, interest point and D of ``members`` from their rays' crossings, and whether they pass."""
    lines = [_ray(p, params.ray_length) for p in members]
    crossings = []
    for i, first in enumerate(lines):
        for second in lines[i + 1 :]:
            meet = first.intersection(second)
            if isinstance(meet, Point):
                crossings.append(meet)
    if not crossings:
        return _Evaluation(False, None, math.inf, math.inf)
    if len(crossings) == 1:
        area, centre = 0.0, crossings[0]
    else:
        hull = MultiPoint(crossings).convex_hull
        area, centre = hull.area, hull.centroid
        if area >= params.area_threshold:
            return _Evaluation(False, (centre.x, centre.y), area, math.inf)
    spread = float(np.mean([Point(p.x, p.y).distance(centre) for p in members]))
    return _Evaluation(spread < params.spread_threshold, (centre.x, centre.y), area, spread)
