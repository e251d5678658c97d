"""The processor this process runs on: how many physical cores it may use (thread counts, benchmark reports)."""

from __future__ import annotations

import ctypes
import os
from collections.abc import Iterable
from pathlib import Path

__all__ = ["keep_freed_memory", "physical_cores", "usable_cpus"]

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


# glibc's mallopt parameters (malloc.h).
_M_TRIM_THRESHOLD, _M_TOP_PAD, _M_MMAP_THRESHOLD = -1, -2, -3
_MMAP_THRESHOLD_MAX = 32 * 2**20  # glibc's ceiling for M_MMAP_THRESHOLD on 64-bit systems


def keep_freed_memory(keep_bytes: int = 256 * 2**20) -> bool:
    """Make glibc's malloc keep freed memory for reuse (up to ``keep_bytes`` at the top of the heap) instead of
    handing large blocks back to the kernel at every free; returns whether it applied (False off glibc).

    numpy's temporaries of a few hundred kB to a few MB (image-sized arrays in the renderer, the costmap's grids)
    are otherwise mapped and unmapped at every call, and each new mapping is paid again in page faults, in the
    kernel (docs/benchmarks.md, "The allocator", has the measurement). The same
    settings as the ``MALLOC_MMAP_THRESHOLD_`` / ``MALLOC_TRIM_THRESHOLD_`` / ``MALLOC_TOP_PAD_`` environment
    variables, set from inside the process. Process-wide: call it once, from an entry point (the ``sid`` command,
    a worker process), never from library code.
    """
    try:
        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # not glibc (musl, macOS, Windows): leave the allocator alone
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    applied = mallopt(_M_MMAP_THRESHOLD, min(keep_bytes, _MMAP_THRESHOLD_MAX))
    applied &= mallopt(_M_TRIM_THRESHOLD, keep_bytes)
    applied &= mallopt(_M_TOP_PAD, min(keep_bytes, 64 * 2**20))
    return bool(applied)
