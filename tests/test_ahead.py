"""run_ahead: the same items in the same order, made in another thread ahead of the consumer, exceptions in place,
and a worker that stops when the consumer does."""

from __future__ import annotations

import queue
import threading
from collections.abc import Iterator

import pytest

from sid.ahead import run_ahead

TIMEOUT = 10.0  # s; only reached when the code under test is broken


def test_same_items_in_order():
    assert list(run_ahead(range(100))) == list(range(100))
    assert list(run_ahead(iter([]))) == []
    assert list(run_ahead(["a", None, "b"], depth=3)) == ["a", None, "b"]  # None is an item like any other


def test_items_are_made_in_a_worker_while_the_consumer_holds_the_last_one():
    made: list[tuple[int, str]] = []
    second_made = threading.Event()

    def items() -> Iterator[int]:
        for k in range(3):
            made.append((k, threading.current_thread().name))
            if k == 1:
                second_made.set()
            yield k

    stream = run_ahead(items())
    assert next(stream) == 0
    assert second_made.wait(TIMEOUT)  # made while the consumer still works on item 0
    assert {name for _, name in made} == {"sid-run-ahead"}
    assert list(stream) == [1, 2]


def test_an_exception_comes_after_the_items_made_before_it():
    def items() -> Iterator[int]:
        yield 1
        yield 2
        raise OSError("camera unplugged")

    got = []
    with pytest.raises(OSError, match="camera unplugged"):
        for item in run_ahead(items()):
            got.append(item)
    assert got == [1, 2]


def test_stopping_early_stops_the_worker_and_closes_the_items():
    closed = threading.Event()
    made = []

    def items() -> Iterator[int]:
        try:
            for k in range(10**6):
                made.append(k)
                yield k
        finally:
            closed.set()

    before = threading.active_count()
    for item in run_ahead(items(), depth=2):
        if item == 3:
            break
    assert closed.wait(TIMEOUT)
    assert threading.active_count() == before  # the worker has ended, not left running
    assert len(made) <= 3 + 1 + 2 + 1  # at most the depth plus the one being made beyond what was used


def test_closing_stops_the_worker_after_the_item_it_is_making():
    """depth 1: the consumer holds item 0, item 1 waits in the queue, and the worker has made item 2 and waits to
    put it. Closing then lets that put through; the worker made item 3 too before it looked at the stop."""
    made: list[int] = []
    third_made = threading.Event()
    closed = threading.Event()

    def items() -> Iterator[int]:
        try:
            for k in range(10):
                made.append(k)
                if k == 2:
                    third_made.set()
                yield k
        finally:
            closed.set()

    stream = run_ahead(items(), depth=1)
    assert next(stream) == 0
    assert third_made.wait(TIMEOUT)
    stream.close()
    assert closed.wait(TIMEOUT)
    assert made == [0, 1, 2]


def test_an_exception_in_the_consumer_stops_the_worker():
    closed = threading.Event()

    def items() -> Iterator[int]:
        try:
            yield from range(10**6)
        finally:
            closed.set()

    with pytest.raises(ZeroDivisionError):
        for item in run_ahead(items()):
            if item == 5:
                raise ZeroDivisionError
    assert closed.wait(TIMEOUT)


class _InterruptedGet(queue.Queue):
    """A queue whose get, once ``interrupt`` is set, takes the item and raises KeyboardInterrupt before telling a
    waiting producer that there is room: what a signal's handler raising in the consumer's thread between the two
    does (a CI run of ``sid detect`` never exited on SIGTERM, the worker waiting for that word for ever)."""

    interrupt = False

    def get(self, block: bool = True, timeout: float | None = None) -> object:
        if not _InterruptedGet.interrupt:
            return super().get(block, timeout)
        _InterruptedGet.interrupt = False
        with self.not_empty:
            while not self._qsize():
                self.not_empty.wait()
            self._get()
        raise KeyboardInterrupt


def test_a_consumer_interrupted_inside_the_queue_still_stops_the_worker(monkeypatch):
    monkeypatch.setattr(queue, "Queue", _InterruptedGet)
    closed, full = threading.Event(), threading.Event()

    def items() -> Iterator[int]:
        try:
            for k in range(10**6):
                if k == 2:
                    full.set()  # item 1 waits in the queue: the worker is about to wait with item 2
                yield k
        finally:
            closed.set()

    def consume() -> None:
        stream = run_ahead(items(), depth=1)
        assert next(stream) == 0
        assert full.wait(TIMEOUT)
        _InterruptedGet.interrupt = True
        with pytest.raises(KeyboardInterrupt):
            next(stream)

    consumer = threading.Thread(target=consume, daemon=True)
    consumer.start()
    consumer.join(TIMEOUT)
    assert not consumer.is_alive()  # the clean-up ended: no wait for a word that never comes
    assert closed.wait(TIMEOUT)


def test_depth_must_be_positive():
    with pytest.raises(ValueError, match="depth must be at least 1"):
        run_ahead(range(3), depth=0)
