"""Independent tasks spread over worker processes: results in input order, progress as tasks finish.

Each worker is a fresh interpreter (spawn, not fork, whatever threads the parent runs: onnxruntime, Ray), sets the
allocator as the ``sid`` command does and runs under the parent's limits (``sid.checks.use_limits``: a fresh
interpreter starts with the defaults). The data every task reads (``shared``: datasets, replayed tracks) goes to
each worker once, not with every task. A task depends only on its input, so the results are those of one process.
When a task fails or the caller is interrupted (Ctrl-C, SIGTERM), the workers end at once and the queued tasks never
start. Spawn runs the main program again in each worker, so a program read from standard input gets ValueError.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from multiprocessing import get_context
from typing import Any, TypeVar

from sid.checks import Limits, check_whole, limits, use_limits
from sid.cpu import keep_freed_memory
from sid.errors import InputError
from sid.experiments.progress import Progress

__all__ = ["map_in_workers"]

_Shared = TypeVar("_Shared")
_Item = TypeVar("_Item")
_Result = TypeVar("_Result")

_shared: Any = None  # in a worker: what every task reads, set once when the worker starts
_in_force = Limits()  # in a worker: the parent's limits


def _start_worker(shared: Any, in_force: Limits) -> None:
    global _shared, _in_force
    keep_freed_memory()
    _shared, _in_force = shared, in_force


def _run(task: Callable[[Any, Any], Any], item: Any) -> Any:
    with use_limits(_in_force):
        return task(_shared, item)


def _terminate_workers(pool: ProcessPoolExecutor) -> None:
    """End the pool's worker processes at once, the tasks they run with them (else shutting the pool down waits for
    them; a worker gone makes the pool broken, which shutdown then notices). ``terminate_workers`` from Python 3.14;
    before, the pool's processes (``_processes``, CPython's since 3.2)."""
    terminate = getattr(pool, "terminate_workers", None)
    if terminate is not None:
        terminate()
        return
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        process.terminate()


def map_in_workers(
    task: Callable[[_Shared, _Item], _Result],
    shared: _Shared,
    items: Sequence[_Item],
    workers: int = 1,
    progress: Progress | None = None,
    what: str | Callable[[_Item], str] = "",
) -> list[_Result]:
    """``task(shared, item)`` for every item, results in the items' order: in this process with ``workers`` 1, else
    in that many worker processes (at most one per item). ``task`` must be a module-level function and ``shared``,
    the items and the results picklable. ``progress(done, len(items), what)`` after each task (``what(item)`` of
    the task just done when ``what`` is a function)."""
    check_whole("tasks", "workers", workers, low=1)

    def report(done: int, item: _Item) -> None:
        if progress is not None:
            progress(done, len(items), what(item) if callable(what) else what)

    if workers == 1 or len(items) < 2:
        results = []
        for done, item in enumerate(items, 1):
            results.append(task(shared, item))
            report(done, item)
        return results
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if getattr(main, "__spec__", None) is None and path and not os.path.isfile(path):
        # spawn runs the main program's file again in each worker; "<stdin>" (python - <<EOF) is none: they all fail
        raise InputError(
            f"tasks: worker processes cannot start from a program that is not a file ({path}): run it from a file, "
            "or with one worker"
        )
    out: list[Any] = [None] * len(items)
    pool = ProcessPoolExecutor(min(workers, len(items)), get_context("spawn"), _start_worker, (shared, limits()))
    try:
        futures = {pool.submit(_run, task, item): k for k, item in enumerate(items)}
        for done, future in enumerate(as_completed(futures), 1):
            k = futures[future]
            out[k] = future.result()
            report(done, items[k])
    except BaseException:  # a task failed, or the caller was interrupted (Ctrl-C, SIGTERM): stop now
        _terminate_workers(pool)
        raise
    finally:
        pool.shutdown(cancel_futures=True)  # the tasks still queued never start
    return out
