"""The execution layer of a sweep: map independent trials to results.

This is the seam for bigger sweeps. An :class:`Executor` only has to apply a
picklable function to each item and return the results in the order of the
items. A distributed executor (a job queue, a cluster scheduler) implements the
same ``map``: ship ``fn`` and the items to its workers, call ``progress`` as
results arrive, and turn an item whose worker was lost into ``lost(item,
reason)`` rather than failing the whole map. Nothing else in ``dial.tune``
knows how the trials run.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from typing import Protocol, TypeVar

T = TypeVar("T")
R = TypeVar("R")

Progress = Callable[[int], None]  # called with the number of items done so far


class Executor(Protocol):
    def map(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        lost: Callable[[T, str], R],
        progress: Progress | None = None,
    ) -> list[R]:
        """``[fn(item) for item in items]``, in item order, however they are run.

        ``fn`` and the items must be picklable. ``lost(item, reason)`` stands in
        for the result of an item whose worker died.
        """
        ...


class SerialExecutor:
    """Run the items one after another in this process (tests, debugging)."""

    def map(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        lost: Callable[[T, str], R],
        progress: Progress | None = None,
    ) -> list[R]:
        results = []
        for item in items:
            results.append(fn(item))
            if progress is not None:
                progress(len(results))
        return results


class ProcessExecutor:
    """A pool of ``jobs`` local worker processes.

    Workers are started with ``spawn`` by default: a fresh interpreter inherits
    no MuJoCo, OpenGL or trio state from the parent, which ``fork`` would copy.
    If a worker dies (a crash in native code), the items it may have been running
    are retried with one worker, one at a time, so the item that kills its worker
    is found and reported through ``lost``; every other item still gets its result.
    """

    def __init__(self, jobs: int | None = None, method: str = "spawn") -> None:
        self.jobs = jobs or os.cpu_count() or 1
        self.method = method

    def map(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        lost: Callable[[T, str], R],
        progress: Progress | None = None,
    ) -> list[R]:
        results: dict[int, R] = {}
        todo = list(range(len(items)))
        workers = min(self.jobs, len(items))
        while todo:
            broken = self._run(fn, items, lost, todo, workers, results, progress)
            todo = [i for i in todo if i not in results]
            if broken is not None and workers == 1:
                # One worker runs its items in order, so the first unfinished one killed it.
                culprit = todo.pop(0)
                results[culprit] = lost(items[culprit], f"worker process died ({broken})")
                if progress is not None:
                    progress(len(results))
            workers = 1
        return [results[i] for i in range(len(items))]

    def _run(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        lost: Callable[[T, str], R],
        todo: list[int],
        workers: int,
        results: dict[int, R],
        progress: Progress | None,
    ) -> str | None:
        """Run ``todo`` in a fresh pool; return why the pool broke, or None."""
        pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context(self.method))
        futures: dict[Future[R], int] = {pool.submit(fn, items[i]): i for i in todo}
        try:
            for future in as_completed(futures):
                i = futures[future]
                try:
                    results[i] = future.result()
                except BrokenProcessPool as e:
                    for other, j in futures.items():  # keep what finished before the break
                        if other.done() and not other.cancelled() and other.exception() is None:
                            results[j] = other.result()
                    return str(e) or type(e).__name__
                except Exception as e:  # fn raised, or an item or result did not pickle
                    results[i] = lost(items[i], f"{type(e).__name__}: {e}")
                if progress is not None:
                    progress(len(results))
        finally:
            # On an interrupt, queued items must not start; running ones have had SIGINT too.
            pool.shutdown(wait=True, cancel_futures=True)
        return None
