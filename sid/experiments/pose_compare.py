"""Two pose models on the same frames, through the whole pipeline: do they find the same people, keypoints, 3D
positions, facings and groups? (``sid model compare``, and the check ``sid model quantize`` reports.)

Per frame: the people each model finds, matched one to one by the highest object keypoint similarity (OKS, COCO's
definition: mean over the reference's keypoints scoring at least the lifting threshold of
``exp(-d^2 / (2 s^2 k^2))``, ``d`` the distance in pixels, ``s^2`` the reference's box area in pixels, ``k`` twice
COCO's per-keypoint sigma); then the people the pipeline lifts from each model's detections (world frame, metres,
radians), compared person by person through that matching, and their groups as sets of matched people.

Positions and facings are held to the criteria only for the people the reference lifts with an orientation quality
of at least ``Criteria.min_quality``: a person seen by 3-5 keypoints (a seated row at the image's edge) has a facing
that moves by several degrees, and appears or disappears, when the float model's own input changes by one grey
level (docs/models.md); the table reports the largest differences over everybody as well.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from sid.perception.frame import Frame
from sid.perception.keypoints import PoseDetection
from sid.perception.people import Person
from sid.perception.pipeline import FrameResult, Pipeline

__all__ = [
    "COCO_SIGMAS",
    "Criteria",
    "FrameComparison",
    "compare_pipelines",
    "compare_results",
    "format_comparisons",
    "match_detections",
    "oks",
]

COCO_SIGMAS = np.array(
    [0.026, 0.025, 0.025, 0.035, 0.035, 0.079, 0.079, 0.072, 0.072,
     0.062, 0.062, 0.107, 0.107, 0.087, 0.087, 0.089, 0.089]
)  # fmt: skip
"""COCO's per-keypoint OKS constants (``pycocotools``' ``kpt_oks_sigmas``), in COCO-17 order."""


@dataclass(frozen=True)
class Criteria:
    """When a candidate model counts as giving the reference's results: per frame the same number of people
    detected, mean OKS at least ``min_oks``, the same groups, and every person the reference lifts with an
    orientation quality of at least ``min_quality`` lifted by the candidate too, within ``max_position_m`` metres and
    ``max_facing_rad`` radians."""

    min_oks: float = 0.9
    max_position_m: float = 0.05
    max_facing_rad: float = math.radians(5.0)
    min_quality: float = 0.3


@dataclass(frozen=True)
class FrameComparison:
    """One frame: people detected and lifted by the reference and the candidate, the mean and lowest OKS of the
    matched detections (None without a matched keypoint), the largest position (m) and facing (rad) differences of
    the matched lifted people (None without one: a facing unknown to either model is left out), the same over the
    people the reference lifts with an orientation quality of at least ``min_quality`` (``well_*``), how many of
    those the candidate did not lift or gave no facing, and whether the groups agree."""

    name: str
    detected: tuple[int, int]
    lifted: tuple[int, int]
    mean_oks: float | None
    min_oks: float | None
    position_m: float | None
    facing_rad: float | None
    min_quality: float
    well_observed: int
    well_missed: int
    well_position_m: float | None
    well_facing_rad: float | None
    same_groups: bool

    def problems(self, criteria: Criteria) -> list[str]:
        """What fails ``criteria`` in this frame (empty when nothing does)."""
        found = []
        if self.detected[0] != self.detected[1]:
            found.append(f"{self.detected[1]} people detected, reference {self.detected[0]}")
        if self.mean_oks is not None and self.mean_oks < criteria.min_oks:
            found.append(f"mean OKS {self.mean_oks:.3f} < {criteria.min_oks}")
        well = f"of the people lifted with orientation quality >= {self.min_quality}"
        if self.well_missed:
            found.append(f"{self.well_missed} {well} not lifted or without a facing")
        if self.well_position_m is not None and self.well_position_m > criteria.max_position_m:
            found.append(f"a position {well} {self.well_position_m:.3f} m away > {criteria.max_position_m} m")
        if self.well_facing_rad is not None and self.well_facing_rad > criteria.max_facing_rad:
            found.append(
                f"a facing {well} {math.degrees(self.well_facing_rad):.1f} deg away > "
                f"{math.degrees(criteria.max_facing_rad):.1f}"
            )
        if not self.same_groups:
            found.append("different groups")
        return found


def oks(reference: PoseDetection, candidate: PoseDetection, min_score: float) -> float | None:
    """Object keypoint similarity of ``candidate`` to ``reference`` (module docstring) over the reference's
    keypoints scoring at least ``min_score``; None when none does."""
    visible = reference.scores >= min_score
    if not visible.any():
        return None
    u0, v0, u1, v1 = reference.box
    area = max((u1 - u0) * (v1 - v0), 1.0)
    squared = np.sum((reference.keypoints - candidate.keypoints) ** 2, axis=1)
    similarity = np.exp(-squared / (2.0 * area * (2.0 * COCO_SIGMAS) ** 2))
    return float(similarity[visible].mean())


def match_detections(
    reference: list[PoseDetection], candidate: list[PoseDetection], min_score: float
) -> tuple[dict[int, int], list[float]]:
    """One-to-one matching of candidate to reference detections maximising the summed OKS: {candidate index:
    reference index} and the OKS of each matched pair that has one."""
    if not reference or not candidate:
        return {}, []
    table = np.array([[oks(r, c, min_score) or 0.0 for c in candidate] for r in reference])
    rows, cols = linear_sum_assignment(-table)
    pairs = list(zip(rows.tolist(), cols.tolist(), strict=True))
    values = [v for r, c in pairs if (v := oks(reference[r], candidate[c], min_score)) is not None]
    return {c: r for r, c in pairs}, values


def compare_results(
    name: str, reference: FrameResult, candidate: FrameResult, min_score: float, min_quality: float = 0.3
) -> FrameComparison:
    """``FrameComparison`` of two pipeline results on the same frame (people ids: detection indices)."""
    matched, similarities = match_detections(reference.detections, candidate.detections, min_score)
    lifted: dict[int, Person] = {matched[p.id]: p for p in candidate.people if p.id in matched}
    positions, facings, well_positions, well_facings, well_missed = [], [], [], [], 0
    for person in reference.people:
        well = person.theta is not None and person.orientation_quality >= min_quality
        other = lifted.get(person.id)
        if other is None or (well and other.theta is None):
            well_missed += well
        if other is None:
            continue
        position = math.hypot(person.x - other.x, person.y - other.y)
        facing = None
        if person.theta is not None and other.theta is not None:
            facing = abs(math.remainder(person.theta - other.theta, math.tau))
            facings.append(facing)
        positions.append(position)
        if well:
            well_positions.append(position)
            if facing is not None:
                well_facings.append(facing)
    reference_groups = {frozenset(g.members) for g in reference.groups}
    candidate_groups = {frozenset(matched.get(m, -1 - m) for m in g.members) for g in candidate.groups}
    return FrameComparison(
        name,
        (len(reference.detections), len(candidate.detections)),
        (len(reference.people), len(candidate.people)),
        float(np.mean(similarities)) if similarities else None,
        min(similarities) if similarities else None,
        max(positions) if positions else None,
        max(facings) if facings else None,
        min_quality,
        sum(p.theta is not None and p.orientation_quality >= min_quality for p in reference.people),
        well_missed,
        max(well_positions) if well_positions else None,
        max(well_facings) if well_facings else None,
        reference_groups == candidate_groups,
    )


def compare_pipelines(
    reference: Pipeline, candidate: Pipeline, frames: Iterable[tuple[str, Frame]], criteria: Criteria = Criteria()
) -> list[FrameComparison]:
    """Both pipelines on each named frame; the lifting threshold of ``reference`` picks the keypoints OKS counts."""
    score, quality = reference.lift_params.min_score, criteria.min_quality
    return [compare_results(name, reference(frame), candidate(frame), score, quality) for name, frame in frames]


def format_comparisons(rows: list[FrameComparison], criteria: Criteria) -> str:
    """A table, one line per frame, then a verdict line ("same results" or how many frames differ)."""

    def value(x: float | None, scale: float = 1.0, digits: int = 3) -> str:
        return "-" if x is None else f"{x * scale:.{digits}f}"

    degrees = 180 / math.pi
    lines = [f"| frame | people | lifted | mean OKS | min OKS | max position diff m | max facing diff deg | "
             f"well observed (quality >= {criteria.min_quality}): people, missed, max position diff m, max facing "
             "diff deg | groups |",
             "|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for row in rows:
        lines.append(
            f"| {row.name} | {row.detected[1]} / {row.detected[0]} | {row.lifted[1]} / {row.lifted[0]} | "
            f"{value(row.mean_oks)} | {value(row.min_oks)} | {value(row.position_m)} | "
            f"{value(row.facing_rad, degrees, 2)} | {row.well_observed}, {row.well_missed}, "
            f"{value(row.well_position_m)}, {value(row.well_facing_rad, degrees, 2)} | "
            f"{'same' if row.same_groups else 'DIFFERENT'} |"
        )
    failed = [(row.name, problems) for row in rows if (problems := row.problems(criteria))]
    oks_values = [row.mean_oks for row in rows if row.mean_oks is not None]
    summary = f"mean OKS over frames {np.mean(oks_values):.3f}; " if oks_values else ""
    if not failed:
        lines.append(
            f"{summary}same results on all {len(rows)} frame(s) (criteria: same people and groups, mean OKS >= "
            f"{criteria.min_oks}; the well observed lifted, positions within {criteria.max_position_m} m, facings "
            f"within {math.degrees(criteria.max_facing_rad):.0f} deg)"
        )
    else:
        lines.append(f"{summary}DIFFERENT results on {len(failed)} of {len(rows)} frame(s):")
        lines += [f"  {name}: {'; '.join(problems)}" for name, problems in failed]
    return "\n".join(lines)
