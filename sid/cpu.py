"""The processor this process runs on: how many physical cores it may use (thread counts, benchmark reports)."""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

_TOPOLOGY = Path("/sys/devices/system/cpu")


def usable_cpus() -> list[int]:
    """Ids of the logical CPUs this process may run on (its affinity mask on Linux, else every CPU)."""
    if hasattr(os, "sched_getaffinity"):
        return sorted(os.sched_getaffinity(0))
    return list(range(os.cpu_count() or 1))


def physical_cores(cpus: Iterable[int] | None = None) -> int:
    """Physical cores among the logical ``cpus`` (default: ``usable_cpus()``), SMT siblings counted once; >= 1.

    A core is identified by its set of hardware threads (Linux sysfs ``topology/thread_siblings_list``), which
    works on x86 and ARM alike (a Jetson's /proc/cpuinfo has no core ids). A CPU whose topology cannot be read, and
    every CPU on other systems, counts as a core of its own.
    """
    cores = set()
    for cpu in usable_cpus() if cpus is None else cpus:
        try:
            cores.add((_TOPOLOGY / f"cpu{cpu}" / "topology" / "thread_siblings_list").read_text().strip())
        except OSError:
            cores.add(f"cpu{cpu}")
    return max(1, len(cores))
