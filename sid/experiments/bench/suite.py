"""Choosing and running benchmarks: ``--only`` selection, progress, ratios between stages, failures kept apart."""

from __future__ import annotations

import fnmatch
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from sid.errors import InputError
from sid.experiments.bench.stages import Benchmark, Context

__all__ = ["Progress", "SuiteResult", "run_suite", "select"]

Progress = Callable[[int, int, str, str], None]
"""progress(index, total, benchmark name, status): called before each benchmark (status "") and after it."""


def _matches(name: str, pattern: str) -> bool:
    """A glob (``pose/*``) matches as fnmatch does; a plain name matches itself and everything under it
    (``group`` matches ``group/4``, not ``group_baseline/4``)."""
    if any(c in pattern for c in "*?["):
        return fnmatch.fnmatchcase(name, pattern)
    return name == pattern or name.startswith(pattern.rstrip("/") + "/")


def select(items: Sequence[Benchmark], only: str | None) -> list[Benchmark]:
    """The benchmarks matching any of the comma-separated patterns of ``only`` (all when None), plus the ones their
    ratios refer to, in suite order. Raises ValueError listing the names when a pattern matches nothing."""
    if only is None:
        return list(items)
    patterns = [p.strip() for p in only.split(",") if p.strip()]
    if not patterns:
        raise InputError("bench: --only needs at least one stage name or pattern")
    unmatched = [p for p in patterns if not any(_matches(b.name, p) for b in items)]
    if unmatched:
        names = ", ".join(b.name for b in items)
        raise InputError(f"bench: --only {', '.join(unmatched)} matches no benchmark; choose from: {names}")
    chosen = {b.name for b in items if any(_matches(b.name, p) for p in patterns)}
    chosen |= {need for b in items if b.name in chosen for need in b.needs}
    return [b for b in items if b.name in chosen]


@dataclass
class SuiteResult:
    """Stage records by name (in run order) and the benchmarks that failed, with their error."""

    stages: dict[str, dict[str, Any]] = field(default_factory=dict)
    failures: dict[str, str] = field(default_factory=dict)


def run_suite(items: Sequence[Benchmark], ctx: Context, progress: Progress | None = None) -> SuiteResult:
    """Run ``items`` one after the other; a benchmark that raises is recorded in ``failures`` (its message, and
    a note in ``ctx``) and the suite goes on. Afterwards every stage with ``ratio_to`` gets ``ratio`` = its median
    / the median of that stage."""
    result = SuiteResult()
    for index, item in enumerate(items):
        if progress:
            progress(index, len(items), item.name, "")
        start = time.perf_counter()
        try:
            records = item.run(ctx)
        except Exception as exc:  # one broken stage must not lose the others' results
            message = f"{type(exc).__name__}: {exc}"
            result.failures[item.name] = message
            ctx.note(f"{item.name} failed: {message}")
            if progress:
                progress(index, len(items), item.name, "FAILED " + message)
                traceback.print_exc()
            continue
        result.stages.update(records)
        if progress:
            summary = ", ".join(f"{k} {v['median_ms']:.3f} ms" for k, v in records.items())
            progress(index, len(items), item.name, f"{summary} ({time.perf_counter() - start:.1f} s)")
    for record in result.stages.values():
        reference = result.stages.get(record.get("ratio_to", ""))
        if reference is not None and reference["median_ms"] > 0:
            record["ratio"] = record["median_ms"] / reference["median_ms"]
    return result
