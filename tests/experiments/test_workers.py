from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from sid.checks import Limits, limits, use_limits
from sid.experiments.workers import map_in_workers


def _scaled(factor: int, item: int) -> tuple[int, int, int]:
    """The item times the shared factor, the process that did it and the limit on people it ran under."""
    return item * factor, os.getpid(), limits().people


def _marked(folder: Path, item: int) -> int:
    """Fails on item 0; every other item leaves a file in ``folder`` after a short wait."""
    if item == 0:
        raise RuntimeError("task 0 failed")
    time.sleep(0.05)
    (folder / str(item)).touch()
    return item


def test_results_come_in_the_items_order_from_one_process_or_several():
    calls: list[tuple[int, int, str]] = []
    alone = map_in_workers(_scaled, 3, [5, 1, 4, 2], progress=lambda *call: calls.append(call), what="items")
    assert [r[0] for r in alone] == [15, 3, 12, 6] and {r[1] for r in alone} == {os.getpid()}
    assert calls == [(1, 4, "items"), (2, 4, "items"), (3, 4, "items"), (4, 4, "items")]
    calls.clear()
    with use_limits(Limits(people=7)):  # a worker is a fresh interpreter: the parent's limits go with the tasks
        pooled = map_in_workers(
            _scaled, 3, [5, 1, 4, 2], workers=2, progress=lambda *call: calls.append(call), what=str
        )
    assert [r[0] for r in pooled] == [15, 3, 12, 6] and os.getpid() not in {r[1] for r in pooled}
    assert {r[2] for r in pooled} == {7}
    assert sorted(done for done, _, _ in calls) == [1, 2, 3, 4]
    assert sorted(what for _, _, what in calls) == ["1", "2", "4", "5"]  # what(item) of each task done


def test_no_items_and_bad_worker_counts():
    assert map_in_workers(_scaled, 3, [], workers=2) == []
    for workers in (0, 1.5, True):
        with pytest.raises(ValueError, match="tasks: workers must be"):
            map_in_workers(_scaled, 3, [1], workers=workers)  # type: ignore[arg-type]


def test_a_failure_stops_the_tasks_still_queued(tmp_path: Path) -> None:
    # The pool is terminated when the caller stops (a task failed here; Ctrl-C or SIGTERM alike): the queued tasks
    # never start, where a pool shut down politely would first have run all 200.
    with pytest.raises(RuntimeError, match="task 0 failed"):
        map_in_workers(_marked, tmp_path, list(range(200)), workers=2)
    assert len(list(tmp_path.iterdir())) < 100


def test_a_program_read_from_standard_input_is_told_to_use_a_file() -> None:
    program = "from sid.experiments.workers import map_in_workers\nmap_in_workers(divmod, 3, [1, 2], workers=2)\n"
    run = subprocess.run([sys.executable, "-"], input=program, capture_output=True, text=True, timeout=120)
    assert run.returncode == 1 and "worker processes cannot start from a program that is not a file (<stdin>)" in (
        run.stderr
    )
