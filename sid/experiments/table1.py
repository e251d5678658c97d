"""Table 1 of the paper on synthetic data: accuracy of people and groups in the layouts S1-S5.

For each layout, for each of its first ``variations`` documented variations (``sid.synthetic.layouts.VARIATIONS``:
as described, turned by -/+ its turn angle, 0.15 m nearer and further, two samples of 5 cm / 5 deg jitter), the
synthetic source renders ``frames`` frames of the static scene, each with fresh D435-like depth noise and keypoint
noise (``sid.synthetic.noise``; seeded by ``seed``, the variation and the frame index), with occlusion between
people and self-occlusion built in (``sid.synthetic.sensor``). Every frame runs through the full pipeline
(``sid.perception.pipeline.Pipeline``: ``TruthPose`` -> ``lift_people`` -> ``detect_groups``).

Matching: detected people are matched to the true people by the Hungarian method on their ground-plane distance
(``scipy.optimize.linear_sum_assignment``), pairs farther apart than ``match_radius`` left unmatched. Ids cannot be
used: the pose stand-in drops people it cannot see, so detection order is not truth order (and a real pose model
keeps no ids at all). A true group is *found* in a frame when a detected group holds at least two of its members
(under the matching); *exact* when it holds exactly its members. The group with the most true members is compared.

Errors (RMSE): IZA, area of the interaction zone (m^2); IPX / IPY, interest point (m); HPX / HPY, person position
(m); HFD, facing direction (deg, differences wrapped to [-180, 180)). The true interest point and area are the
group detector's own on exact positions and facing directions (``sid.synthetic.truth``), so the group errors come
from perception alone. Group errors are over the frames where the group was found; person errors over matched
people, HFD over matched people with a facing. Misses are counted, never hidden: the detection rates of people
and groups, the frames where the group was not found, people without a facing, and false detections are reported
next to the RMSEs, together with the mean error (bias) of each quantity.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from sid.checks import check_number, check_whole, repeated
from sid.errors import InputError
from sid.experiments.fformation import most_shared
from sid.experiments.progress import Progress
from sid.experiments.synthetic_tracking import identify
from sid.perception.group import Group
from sid.perception.groups import GroupParams
from sid.perception.lifting import LiftParams
from sid.perception.people import Person
from sid.perception.pipeline import Pipeline
from sid.sources.synthetic import SyntheticSource
from sid.synthetic.layouts import LAYOUTS, VARIATIONS, variations
from sid.synthetic.noise import DepthNoise, KeypointNoise
from sid.synthetic.pose import TruthPose
from sid.synthetic.sensor import FrameTruth

__all__ = [
    "ErrorLog",
    "METRICS",
    "PAPER_TABLE1",
    "Table1Result",
    "Table1Settings",
    "UNITS",
    "best_group",
    "match_people",
    "run_table1",
    "table1_json",
    "wrap_degrees",
]

METRICS = ("IZA", "IPX", "IPY", "HPX", "HPY", "HFD")
UNITS = {"IZA": "m^2", "IPX": "m", "IPY": "m", "HPX": "m", "HPY": "m", "HFD": "deg"}

PAPER_TABLE1: dict[str, dict[str, float]] = {
    "S1": {"IZA": 0.002, "IPX": 0.023, "IPY": 0.037, "HPX": 0.023, "HPY": 0.063, "HFD": 2.489},
    "S2": {"IZA": 0.021, "IPX": 0.075, "IPY": 0.123, "HPX": 0.087, "HPY": 0.102, "HFD": 2.987},
    "S3": {"IZA": 0.043, "IPX": 0.032, "IPY": 0.087, "HPX": 0.092, "HPY": 0.024, "HFD": 4.423},
    "S4": {"IZA": 0.038, "IPX": 0.089, "IPY": 0.186, "HPX": 0.123, "HPY": 0.129, "HFD": 6.897},
    "S5": {"IZA": 0.067, "IPX": 0.124, "IPY": 0.087, "HPX": 0.154, "HPY": 0.086, "HFD": 6.942},
}
"""The paper's Table 1 (RMSE per scenario; its source: docs/reproduction.md)."""


@dataclass(frozen=True)
class Table1Settings:
    """What the reproduction runs.

    scenarios: layout names. frames: frames per layout variation. variations: how many of the documented
    variations to use (1..7, in ``VARIATIONS`` order). seed: noise seed. depth_noise / keypoint_noise: the sensor
    and pose-model noise (``sid.synthetic.noise``). match_radius: largest distance (m) of a person match.
    lift_params / group_params: the pipeline's parameters (their defaults).
    """

    scenarios: tuple[str, ...] = tuple(LAYOUTS)
    frames: int = 50
    variations: int = len(VARIATIONS)
    seed: int = 0
    depth_noise: DepthNoise = field(default_factory=DepthNoise)
    keypoint_noise: KeypointNoise = field(default_factory=KeypointNoise)
    match_radius: float = 0.5
    lift_params: LiftParams = field(default_factory=LiftParams)
    group_params: GroupParams = field(default_factory=GroupParams)

    def __post_init__(self) -> None:
        unknown = [s for s in self.scenarios if s.upper() not in LAYOUTS]
        if unknown or not self.scenarios:
            raise InputError(f"table1: unknown scenario(s) {unknown or '(none given)'}; known: {', '.join(LAYOUTS)}")
        twice = repeated([s.upper() for s in self.scenarios])
        if twice is not None:  # its frames would be pooled twice into the one row
            raise InputError(f"table1: scenario {twice} is given twice")
        check_whole("table1", "frames", self.frames, low=1)
        if not 1 <= self.variations <= len(VARIATIONS):
            raise InputError(f"table1: variations must be 1..{len(VARIATIONS)}, got {self.variations}")
        check_number("table1", "match_radius", self.match_radius, low=0, low_open=True, unit="metres")

    def describe(self) -> dict[str, Any]:
        """The settings as plain JSON (noise records spelled out)."""
        return {
            "scenarios": list(self.scenarios),
            "frames_per_variation": self.frames,
            "variations": [dict(v) for v in VARIATIONS[: self.variations]],
            "seed": self.seed,
            "depth_noise": asdict(self.depth_noise),
            "keypoint_noise": asdict(self.keypoint_noise),
            "match_radius_m": self.match_radius,
            "lift_params": asdict(self.lift_params),
            "group_params": asdict(self.group_params),
        }


@dataclass
class ErrorLog:
    """Errors of one scenario, accumulated frame by frame (metres, square metres, degrees)."""

    frames: int = 0
    people_truth: int = 0
    people_matched: int = 0
    false_people: int = 0
    no_facing: int = 0
    group_frames: int = 0
    group_undetectable: int = 0
    group_found: int = 0
    group_exact: int = 0
    errors: dict[str, list[float]] = field(default_factory=lambda: {m: [] for m in METRICS})

    def add_frame(self, truth: FrameTruth, people: Sequence[Person], groups: Sequence[Group], radius: float) -> None:
        self.frames += 1
        matches = match_people(people, truth, radius)
        self.people_truth += len(truth.people)
        self.people_matched += len(matches)
        self.false_people += len(people) - len(matches)
        true_by_id = {p.id: p for p in truth.people}
        for detected, true_id in matches.items():
            person, true = _by_id(people, detected), true_by_id[true_id]
            self.errors["HPX"].append(person.x - true.x)
            self.errors["HPY"].append(person.y - true.y)
            if person.theta is None:
                self.no_facing += 1
            else:
                self.errors["HFD"].append(wrap_degrees(person.theta - true.theta))
        for true_group in truth.groups:
            if not true_group.detectable:
                self.group_undetectable += 1
                continue
            self.group_frames += 1
            group, overlap = best_group(groups, matches, true_group.members)
            if group is None or overlap < 2:
                continue
            self.group_found += 1
            self.group_exact += int({matches.get(m) for m in group.members} == set(true_group.members))
            self.errors["IZA"].append(group.area - true_group.area)
            self.errors["IPX"].append(group.interest_point[0] - true_group.interest_point[0])
            self.errors["IPY"].append(group.interest_point[1] - true_group.interest_point[1])

    def summary(self) -> dict[str, Any]:
        """RMSE, bias (mean error) and sample count per metric, and the detection counts and rates."""
        rmse, bias, samples = {}, {}, {}
        for name, values in self.errors.items():
            data = np.asarray(values, dtype=float)
            samples[name] = len(data)
            rmse[name] = float(np.sqrt(np.mean(data**2))) if len(data) else None
            bias[name] = float(np.mean(data)) if len(data) else None
        return {
            **rmse,
            "bias": bias,
            "samples": samples,
            "frames": self.frames,
            "people": {
                "truth": self.people_truth,
                "matched": self.people_matched,
                "detection_rate": _ratio(self.people_matched, self.people_truth),
                "false_detections": self.false_people,
                "without_facing": self.no_facing,
            },
            "group": {
                "frames": self.group_frames,
                "found": self.group_found,
                "exact_members": self.group_exact,
                "not_found": self.group_frames - self.group_found,
                "detection_rate": _ratio(self.group_found, self.group_frames),
                "exact_rate": _ratio(self.group_exact, self.group_frames),
                "undetectable_on_exact_data": self.group_undetectable,
            },
        }


def _ratio(part: int, whole: int) -> float | None:
    return part / whole if whole else None


def _by_id(people: Sequence[Person], pid: int) -> Person:
    return next(p for p in people if p.id == pid)


def wrap_degrees(radians: float) -> float:
    """An angle difference (rad) in degrees, wrapped to [-180, 180)."""
    return float((math.degrees(radians) + 180.0) % 360.0 - 180.0)


def match_people(people: Sequence[Person], truth: FrameTruth, radius: float) -> dict[int, int]:
    """Detected person id -> true person id: ``identify``'s assignment (minimum total ground-plane distance over
    the pairs within ``radius``, m)."""
    if not people or not truth.people:
        return {}
    detected = np.array([(p.x, p.y) for p in people], dtype=float)
    true = np.array([(p.x, p.y) for p in truth.people], dtype=float)
    identity = identify(detected, [p.id for p in truth.people], true, radius)
    return {p.id: i for p, i in zip(people, identity, strict=True) if i is not None}


def best_group(groups: Sequence[Group], matches: dict[int, int], members: Sequence[int]) -> tuple[Group | None, int]:
    """The detected group holding the most of the true ``members`` (under ``matches``; unmatched members count as
    strangers), fewest strangers on ties (``fformation.most_shared``); and how many true members it holds."""
    mapped = [frozenset(matches.get(m, -1 - n) for n, m in enumerate(g.members)) for g in groups]
    k = most_shared(mapped, frozenset(members))
    return (None, 0) if k is None else (groups[k], len(mapped[k] & frozenset(members)))


@dataclass
class Table1Result:
    settings: Table1Settings
    scenarios: dict[str, dict] = field(default_factory=dict)
    by_variation: dict[str, list[dict]] = field(default_factory=dict)


def run_table1(settings: Table1Settings = Table1Settings(), progress: Progress | None = None) -> Table1Result:
    """Run every scenario x variation x frame through the pipeline and summarise the errors per scenario (and per
    variation, in ``by_variation``)."""
    result = Table1Result(settings)
    total = len(settings.scenarios) * settings.variations * settings.frames
    done = 0
    for name in settings.scenarios:
        name = name.upper()
        log = ErrorLog()
        result.by_variation[name] = []
        for k, scene in enumerate(variations(name)[: settings.variations]):
            source = SyntheticSource(
                scene,
                frames=settings.frames,
                seed=settings.seed * 1000 + k,
                noise=settings.depth_noise,
                keypoint_noise=settings.keypoint_noise,
                shaded_color=False,  # the pose stand-in reads the truth, not the image
                group_params=settings.group_params,
            )
            pipeline = Pipeline(TruthPose(), scene.mount, settings.lift_params, settings.group_params)
            variation_log = ErrorLog()
            for frame in source:
                if progress:
                    progress(done, total, f"{name} variation {k + 1}/{settings.variations}")
                found = pipeline(frame)
                for target in (log, variation_log):
                    target.add_frame(frame.truth, found.people, found.groups, settings.match_radius)
                done += 1
            result.by_variation[name].append({"variation": dict(VARIATIONS[k]), **variation_log.summary()})
        result.scenarios[name] = log.summary()
    if progress:
        progress(total, total, "done")
    return result


def table1_json(result: Table1Result) -> dict[str, Any]:
    """``table1.json``: ``{"S1": {"IZA": .., ..., "HFD": .., "bias": .., "people": .., "group": ..}, ...}`` plus
    ``"paper"`` (the paper's values), ``"settings"`` and ``"by_variation"``."""
    return {
        **result.scenarios,
        "paper": PAPER_TABLE1,
        "units": UNITS,
        "settings": result.settings.describe(),
        "by_variation": result.by_variation,
    }
