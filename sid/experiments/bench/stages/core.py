"""What every stage shares: the run's ``Context``, the ``Benchmark`` record, stage records, and the paper's
Table 2 figures (ms per frame on a Jetson Orin NX, another machine; docs/benchmarks.md)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sid.errors import InputError
from sid.experiments.bench.runner import RunSettings, Stats

__all__ = [
    "Benchmark",
    "Context",
    "PAPER_GROUP_MS",
    "PAPER_LIFT_MS",
    "PAPER_POSE_MS",
    "PAPER_TOTAL_MS",
    "Records",
    "record",
]

# The paper's Table 2 (ms per frame on a Jetson Orin NX; docs/benchmarks.md) for 2 / 3 / 4 people.
PAPER_POSE_MS = {2: 3.15, 3: 2.86, 4: 3.32}
PAPER_LIFT_MS = {2: 0.55, 3: 0.52, 4: 0.55}  # "depth alignment + 3D"
PAPER_GROUP_MS = {2: 0.25, 3: 0.14, 4: 0.15}  # "DBSCAN + groups"
PAPER_TOTAL_MS = {2: 3.95, 3: 3.52, 4: 4.02}


Records = dict[str, dict[str, Any]]


@dataclass
class Context:
    """What every benchmark may use: timing settings, where ../shared is, shared set-ups and notes for the report.

    plan_runs: seeds per sampling planner (each run takes the whole 0.5 s budget). pose_threads, pose_provider:
    the pose sessions' thread count (None: physical cores) and execution provider (``load_pose_estimator``'s).
    """

    settings: RunSettings
    shared: Path
    plan_runs: int
    pose_threads: int | None = None
    pose_provider: str = "auto"
    notes: list[str] = field(default_factory=list)
    _cache: dict[str, Any] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        if self.plan_runs < 1:
            raise InputError(f"bench: plan_runs must be at least 1, got {self.plan_runs}")

    def cached(self, key: str, build: Callable[[], Any]) -> Any:
        """``build()`` once per run, shared by the benchmarks that need the same input."""
        if key not in self._cache:
            self._cache[key] = build()
        return self._cache[key]

    def note(self, text: str) -> None:
        if text not in self.notes:
            self.notes.append(text)


@dataclass(frozen=True)
class Benchmark:
    """One unit of ``sid bench``: its name (also the prefix of the stages it writes), a one-line description, the
    function that times it, and the benchmarks whose stages its ratios refer to (run with it)."""

    name: str
    what: str
    run: Callable[[Context], Records]
    needs: tuple[str, ...] = ()


def record(stats: Stats, **extra: Any) -> dict[str, Any]:
    """A stage record: the fixed fields plus extras (None values are left out)."""
    return stats.to_dict() | {k: v for k, v in extra.items() if v is not None}
