"""Timing harness of ``sid bench``: warm-up calls, then repeated timed calls with the garbage collector off.

A stage is timed by calling it repeatedly until ``max_runs`` calls or ``budget_s`` seconds have passed (but at
least ``min_runs`` calls), after ``warmup`` untimed calls. Each call is timed on its own with
``time.perf_counter_ns`` (its resolution is well below the fastest stage's tens of microseconds), and the
report keeps the median, the minimum, the maximum and the number of runs. The collector is switched off while a
stage runs (after a collection) so that a collection triggered by an earlier stage's garbage does not land in a
later stage's samples; this is how ``timeit`` measures too.
"""

from __future__ import annotations

import gc
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

from sid.errors import InputError

__all__ = ["FULL", "QUICK", "RunSettings", "Stats", "measure", "measure_parts"]


@dataclass(frozen=True)
class RunSettings:
    """How long each stage is timed: ``warmup`` untimed calls, then between ``min_runs`` and ``max_runs`` timed
    calls, stopping once ``budget_s`` seconds (timed calls only) have passed."""

    warmup: int
    min_runs: int
    max_runs: int
    budget_s: float

    def __post_init__(self) -> None:
        if self.warmup < 0 or self.min_runs < 1 or self.max_runs < self.min_runs or not self.budget_s > 0:
            raise InputError(
                f"bench: need warmup >= 0, 1 <= min_runs <= max_runs and budget_s > 0, got {self.warmup}, "
                f"{self.min_runs}, {self.max_runs}, {self.budget_s}"
            )


QUICK = RunSettings(warmup=2, min_runs=3, max_runs=20, budget_s=0.15)
"""``sid bench --quick``: a smoke run for tests and CI, a few calls per stage (its length here: docs/benchmarks.md)."""
FULL = RunSettings(warmup=5, min_runs=20, max_runs=500, budget_s=2.0)
"""``sid bench``: up to 2 s and 500 runs per stage (the run's length: docs/benchmarks.md)."""


@dataclass(frozen=True)
class Stats:
    """Summary of one stage's samples, milliseconds."""

    median_ms: float
    min_ms: float
    max_ms: float
    runs: int

    @classmethod
    def of(cls, samples_ms: list[float]) -> Stats:
        if not samples_ms:
            raise InputError("bench: no samples to summarise")
        return cls(statistics.median(samples_ms), min(samples_ms), max(samples_ms), len(samples_ms))

    def to_dict(self) -> dict[str, float | int]:
        """The fixed fields of a stage in ``bench.json``."""
        return {"median_ms": self.median_ms, "min_ms": self.min_ms, "max_ms": self.max_ms, "runs": self.runs}


def measure_parts(fn: Callable[[], dict[str, float]], settings: RunSettings) -> dict[str, Stats]:
    """Time a call that reports its own parts: ``fn()`` returns milliseconds per part name (the same names on
    every call, in any order). Returns the statistics of each part over the timed calls; ValueError when a call
    reports no part or other names than the first call."""
    names: list[str] | None = None

    def call() -> dict[str, float]:
        nonlocal names
        parts = fn()
        if not parts:
            raise InputError("bench: a timed call reported no parts")
        if names is None:
            names = list(parts)
        elif set(parts) != set(names):  # in any order: a stage may time its parts in turns
            raise InputError(f"bench: a timed call reported parts {list(parts)}, an earlier one {names}")
        return parts

    for _ in range(settings.warmup):
        call()
    samples: dict[str, list[float]] = {}
    was_enabled = gc.isenabled()
    gc.collect()
    gc.disable()
    try:
        calls, spent_ns, budget_ns = 0, 0, int(settings.budget_s * 1e9)
        while calls < settings.max_runs and (spent_ns < budget_ns or calls < settings.min_runs):
            start = time.perf_counter_ns()
            parts = call()
            spent_ns += time.perf_counter_ns() - start
            calls += 1
            for name, value in parts.items():
                samples.setdefault(name, []).append(float(value))
    finally:
        if was_enabled:
            gc.enable()
    return {name: Stats.of(values) for name, values in samples.items()}


def measure(fn: Callable[[], object], settings: RunSettings) -> Stats:
    """Time ``fn()`` (its result is ignored): median, min and max over the timed calls, milliseconds."""

    def timed() -> dict[str, float]:
        start = time.perf_counter_ns()
        fn()
        return {"call": (time.perf_counter_ns() - start) / 1e6}

    return measure_parts(timed, settings)["call"]
