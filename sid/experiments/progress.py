"""Progress of long experiment runs on stderr: ``progress(done, total, what)``."""

from __future__ import annotations

import atexit
import sys
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, TextIO

if TYPE_CHECKING:  # rich is imported when a bar is first drawn: ~55 ms that a run off a terminal never needs
    from rich.progress import Progress as RichProgress
    from rich.progress import TaskID

__all__ = ["LINE_STEPS", "REDRAW_S", "Progress", "ProgressBar"]

Progress = Callable[[int, int, str], None]
"""A progress callback, ``progress(done, total, what)``: ``done`` of ``total`` items finished, ``what`` the current
one; the experiments call it as they go, ``ProgressBar`` is one."""

LINE_STEPS = 10
"""Off a terminal: one line per tenth of the work."""
REDRAW_S = 0.1
"""On a terminal: the shortest time between two redraws (the first and the last are always drawn)."""


class ProgressBar:
    """``progress(done, total, what)``. On a terminal: a bar (rich) with the count, the elapsed time and an estimate
    of the time left, drawn on one line and left in place when ``done`` reaches ``total``. Off a terminal (a log
    file, a pipe): no redraws, one plain line at the start, at each tenth of the work and at the end, e.g.
    ``simulate: 120/600 (20 %), 14 s, about 56 s left, t = 12.0 s`` (tenths of a second below 10 s; the time left
    from the first tenth on). A call with
    less done than the last starts a new bar (a new stage of the work); the total may change (a run that ends early:
    ``progress(203, 203, ...)``)."""

    def __init__(self, label: str, stream: TextIO | None = None) -> None:
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.start = time.monotonic()
        self._bar: RichProgress | None = None
        self._task: TaskID | None = None
        self._drawn = -REDRAW_S  # on a terminal: when the bar was last drawn
        self._next_line = 0  # off a terminal: the tenth whose line comes next
        self._last = (0, 0)  # the last call's done and total (a new total with more done: the same work, re-estimated)

    def __call__(self, done: int, total: int, what: str) -> None:
        if total < 1:  # nothing to do: done
            done = total = 1
        if done < self._last[0]:  # a new stage
            self._next_line, self.start = 0, time.monotonic()
            self._stop()
        self._last = (done, total)
        if self.stream.isatty():
            self._draw(done, total, what)
        else:
            self._line(done, total, what)

    def _draw(self, done: int, total: int, what: str) -> None:
        if self._bar is None:
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, TextColumn, TimeElapsedColumn, TimeRemainingColumn
            from rich.progress import Progress as RichProgress

            self._bar = RichProgress(
                TextColumn(self.label),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                TextColumn("left"),
                TimeRemainingColumn(),
                TextColumn("{task.fields[what]}"),
                console=Console(file=self.stream),
                auto_refresh=False,  # drawn by the calls: no thread of its own
                redirect_stdout=False,  # what the command prints goes where it would without a bar
                redirect_stderr=False,
            )
            self._task = self._bar.add_task(self.label, total=total, completed=done, what=what)
            self._bar.start()
            atexit.register(self._bar.stop)  # a run that stops early still gives the terminal its cursor back
        assert self._task is not None  # added with the bar
        self._bar.update(self._task, completed=done, total=total, what=what)
        now = time.monotonic()
        if done >= total or now - self._drawn >= REDRAW_S:
            self._drawn = now
            self._bar.refresh()
        if done >= total:
            self._stop()

    def close(self) -> None:
        """End the bar's line where it stands (a run that stops before its end, e.g. on an error)."""
        self._stop()

    def _stop(self) -> None:
        if self._bar is not None:
            self._bar.stop()
            atexit.unregister(self._bar.stop)
            self._bar = None

    def _line(self, done: int, total: int, what: str) -> None:
        tenth = min(LINE_STEPS, done * LINE_STEPS // total)
        if tenth < self._next_line:
            return
        self._next_line = tenth + 1
        elapsed = time.monotonic() - self.start
        # The time left from a tenth of the work on: extrapolated from the first item (set-up included) it said hours.
        left = f", about {_seconds(elapsed * (total - done) / done)} left" if tenth > 0 and done < total else ""
        line = f"{self.label}: {done}/{total} ({100 * done // total} %), {_seconds(elapsed)}{left}, {what}"
        print(line, file=self.stream, flush=True)


def _seconds(duration: float) -> str:
    """A duration (s) for a progress line: tenths below 10 s (a run of a few seconds reads "0.4 s", not "0 s")."""
    return f"{duration:.1f} s" if duration < 9.95 else f"{duration:.0f} s"
