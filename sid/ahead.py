"""Run an iterator ahead of its consumer in a worker thread: the next item is made while the last one is used.

``sid detect`` reads and poses frame n + 1 (file or camera I/O and onnxruntime, which release the GIL) while the
main thread lifts, groups, tracks and writes frame n, so a frame costs about the longer of the two halves instead
of their sum (docs/benchmarks.md, "Start-up and the detect loop").

The standard library has thread pools but no bounded read-ahead of one iterator that keeps its items in order and
its exceptions in place; this module is that, on ``threading`` and ``queue``.
"""

from __future__ import annotations

import contextlib
import queue
import threading
from collections.abc import Iterable, Iterator
from typing import TypeVar, cast

from sid.errors import InputError

__all__ = ["T", "run_ahead"]

T = TypeVar("T")

_END = object()  # the worker's last message: the iterator ended, with or without an exception
_POLL_S = 0.05
"""Seconds between the worker's looks at a full queue (``_ahead``'s ``hand_over``)."""


def run_ahead(items: Iterable[T], depth: int = 1) -> Iterator[T]:
    """The items of ``items``, in order, each made in a worker thread while the consumer uses the ones before.

    depth: how many finished items may wait for the consumer (>= 1); the worker makes at most one more meanwhile.
    An exception raised by ``items`` is raised here, after the items made before it. Closing the returned
    iterator (a ``break`` out of its loop, an exception in the consumer, garbage collection) stops the worker
    after the item it is making and closes ``items`` if it is a generator.
    """
    if depth < 1:
        raise InputError(f"run_ahead: depth must be at least 1, got {depth}")
    return _ahead(items, depth)


def _ahead(items: Iterable[T], depth: int) -> Iterator[T]:
    ready: queue.Queue[tuple[object, BaseException | None]] = queue.Queue(maxsize=depth)
    stop = threading.Event()

    def hand_over(entry: tuple[object, BaseException | None]) -> bool:
        """Put ``entry`` in the queue, waiting while it is full; False when the consumer stopped meanwhile. The wait
        looks again every ``_POLL_S``: a consumer interrupted by a signal inside ``get`` (an item taken, its
        notification to the waiting worker not yet sent) left the worker waiting for ever, and the consumer's
        clean-up with it (a CI run: ``sid detect`` did not exit on SIGTERM)."""
        while True:
            try:
                ready.put(entry, timeout=_POLL_S)
                return True
            except queue.Full:
                if stop.is_set():
                    return False

    def work() -> None:
        iterator = iter(items)
        error: BaseException | None = None
        try:
            for item in iterator:
                if not hand_over((item, None)) or stop.is_set():  # stopped: make no other item
                    break
        except BaseException as exc:  # handed to the consumer, which raises it in its own thread
            error = exc
        finally:
            close = getattr(iterator, "close", None)
            if close is not None:
                close()
        hand_over((_END, error))

    worker = threading.Thread(target=work, name="sid-run-ahead", daemon=True)
    worker.start()
    try:
        while True:
            item, error = ready.get()
            if item is _END:
                if error is not None:
                    raise error
                return
            yield cast(T, item)  # every item but _END came from ``items``
    finally:
        stop.set()
        while worker.is_alive():  # let a worker blocked on a full queue put its item and see ``stop``
            with contextlib.suppress(queue.Empty):
                ready.get(timeout=0.01)
        worker.join()
