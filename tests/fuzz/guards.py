"""What every fuzz test checks besides its reader's contract: no hang past a time limit and bounded memory."""

from __future__ import annotations

import resource
import signal
from collections.abc import Iterator
from contextlib import contextmanager

HANG_LIMIT_S = 60
"""A generous bound on one example (a hang, not a speed check): the machine running the suite may be busy."""
MEMORY_LIMIT_BYTES = 2 * 1024**3
"""Address space the test process may add while an example runs (far above any accepted input's need)."""


class Hang(Exception):
    """An example ran past HANG_LIMIT_S."""


def _alarm(signum: int, frame: object) -> None:
    raise Hang(f"an example ran longer than {HANG_LIMIT_S} s")


@contextmanager
def bounded(seconds: int = HANG_LIMIT_S) -> Iterator[None]:
    """Run the block with a hang alarm and a cap on new address space (a MemoryError instead of swapping the
    machine); both are lifted afterwards."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    used = _address_space()
    cap = used + MEMORY_LIMIT_BYTES
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(seconds)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def _address_space() -> int:
    """The process's current virtual memory size in bytes (Linux /proc)."""
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[0]) * resource.getpagesize()
