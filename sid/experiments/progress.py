"""A progress bar on stderr for long experiment runs: ``progress(done, total, what)``."""

from __future__ import annotations

import math
import sys
import time
from typing import TextIO

__all__ = ["ProgressBar"]


class ProgressBar:
    """``progress(done, total, what)`` drawing a one-line bar with the elapsed time on ``stream`` (stderr), redrawn
    at most every ``interval`` seconds (and always at the start and the end)."""

    def __init__(self, label: str, stream: TextIO | None = None, width: int = 30, interval: float = 0.2):
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.interval = interval
        self.start = time.perf_counter()
        self.last = -math.inf

    def __call__(self, done: int, total: int, what: str) -> None:
        now = time.perf_counter()
        if 0 < done < total and now - self.last < self.interval:
            return
        self.last = now
        filled = int(self.width * done / max(total, 1))
        bar = "#" * filled + "." * (self.width - filled)
        line = f"\r{self.label} [{bar}] {done}/{total} {now - self.start:5.0f} s {what}"
        end = "\n" if done >= total else ""
        print(f"{line[:118]:<118}", end=end, file=self.stream, flush=True)
