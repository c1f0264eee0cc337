"""The execution layer of a sweep: map independent trials to results.

This is the seam for bigger sweeps. An :class:`Executor` only has to apply a
picklable function to each item and return the results in the order of the
items. A distributed executor (:class:`~dial.tune.ray_executor.RayExecutor`)
implements the same ``map``: ship ``fn`` and the items to its workers, call
``progress`` as results arrive, and turn an item whose worker was lost into
``lost(item, reason)`` rather than failing the whole map. Nothing else in
``dial.tune`` knows how the trials run.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from typing import Protocol, TypeVar

T = TypeVar("T")
R = TypeVar("R")

ItemsDone = Callable[[int], None]  # called with the number of items done so far
# Called in the caller's process with each item's index and result as it arrives (in the
# order they finish); what it returns is kept instead (a dataset writes a trial's frames
# and keeps the rest, so that results do not pile up in memory).
Each = Callable[[int, R], R]
Initializer = Callable[[], None]  # run once in each worker process before its first item

# The reason given for an item that killed its worker every time it ran, whatever the
# executor: the same sweep prints the same table on a process pool and on Ray.
WORKER_DIED = "worker process died"


class Executor(Protocol):
    def map(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        lost: Callable[[T, str], R],
        progress: ItemsDone | None = None,
        each: Each[R] | None = None,
    ) -> list[R]:
        """``[fn(item) for item in items]``, in item order, however they are run.

        ``fn`` and the items must be picklable. ``lost(item, reason)`` stands in
        for the result of an item whose worker died. ``each(index, result)``, if
        given, sees every result once as it arrives, and its value is kept.
        """
        ...


class SerialExecutor:
    """Run the items one after another in this process (tests, debugging)."""

    def map(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        lost: Callable[[T, str], R],
        progress: ItemsDone | None = None,
        each: Each[R] | None = None,
    ) -> list[R]:
        results = []
        for i, item in enumerate(items):
            result = fn(item)
            results.append(result if each is None else each(i, result))
            if progress is not None:
                progress(len(results))
        return results


# In a worker process of ProcessExecutor: one flag per item, set when the worker starts
# it, shared with the parent so that after a crash it knows which items were running.
_started: ctypes.Array[ctypes.c_bool] | None = None


def _init_worker(started: ctypes.Array[ctypes.c_bool], initializer: Initializer | None) -> None:
    global _started
    _started = started
    if initializer is not None:
        initializer()


def _call(fn: Callable[[T], R], index: int, item: T) -> R:
    assert _started is not None, "a ProcessExecutor worker is set up by _init_worker"
    _started[index] = True
    return fn(item)


class ProcessExecutor:
    """A pool of ``jobs`` local worker processes, kept for the whole map.

    Workers are started with ``spawn``: a fresh interpreter inherits no MuJoCo,
    OpenGL or trio state from the parent, which ``fork`` would copy. With
    ``preload`` (module names), a fork server that has imported those modules
    once, and nothing else, forks the workers instead, where the platform has
    one: a worker then starts in milliseconds instead of importing them for a
    second of CPU. ``initializer`` runs once in each worker (to cache what every
    item needs). If a worker dies (a crash in native code), only the items that
    were running then are retried, each alone in a one-worker pool, so the item
    that kills its worker is found and reported through ``lost``; the rest go on
    in a full pool again, and every other item gets its result.
    """

    def __init__(
        self,
        jobs: int | None = None,
        method: str | None = None,
        initializer: Initializer | None = None,
        preload: Sequence[str] = (),
    ) -> None:
        self.jobs = jobs or os.cpu_count() or 1
        forkserver = "forkserver" in multiprocessing.get_all_start_methods()
        self.method = method or ("forkserver" if preload and forkserver else "spawn")
        self.initializer = initializer
        self.preload = list(preload)

    def _context(self) -> multiprocessing.context.BaseContext:
        context = multiprocessing.get_context(self.method)
        if self.method == "forkserver":  # takes effect when this process starts its server
            context.set_forkserver_preload(self.preload)
        return context

    @property
    def where(self) -> str:
        return f"on {self.jobs} worker processes"

    def map(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        lost: Callable[[T, str], R],
        progress: ItemsDone | None = None,
        each: Each[R] | None = None,
    ) -> list[R]:
        started = self._context().RawArray(ctypes.c_bool, max(len(items), 1))
        results: _Results[R] = _Results(each, progress)
        todo = list(range(len(items)))
        while todo:
            workers = min(self.jobs, len(todo))
            if self._run(fn, items, lost, todo, workers, started, results) is None:
                break
            # The pool broke: a suspect is an item that had started and has no result (if
            # none had, the first one left, which may kill its worker before it starts).
            left = [i for i in todo if i not in results]
            for i in [i for i in left if started[i]] or left[:1]:
                if self._run(fn, items, lost, [i], 1, started, results) is not None:
                    results.put(i, lost(items[i], WORKER_DIED))  # it killed its worker alone
            todo = [i for i in todo if i not in results]
        return results.in_order(len(items))

    def _run(
        self,
        fn: Callable[[T], R],
        items: Sequence[T],
        lost: Callable[[T, str], R],
        todo: list[int],
        workers: int,
        started: ctypes.Array[ctypes.c_bool],
        results: _Results[R],
    ) -> str | None:
        """Run ``todo`` in a fresh pool of ``workers``; return why the pool broke, or None."""
        for i in todo:
            started[i] = False
        pool = ProcessPoolExecutor(
            workers,
            mp_context=self._context(),
            initializer=_init_worker,
            initargs=(started, self.initializer),
        )
        futures: dict[Future[R], int] = {pool.submit(_call, fn, i, items[i]): i for i in todo}
        try:
            broken = self._collect(futures, items, lost, results)
        except BaseException:  # an interrupt: stop now, so that a second one finds no wait
            _stop_now(pool)
            raise
        pool.shutdown(wait=True, cancel_futures=True)
        return broken

    @staticmethod
    def _collect(
        futures: dict[Future[R], int],
        items: Sequence[T],
        lost: Callable[[T, str], R],
        results: _Results[R],
    ) -> str | None:
        """Gather ``futures`` into ``results``; return why the pool broke, or None. A future
        is let go once its result is kept, so results do not pile up here."""
        for future in as_completed(futures):
            i = futures.pop(future)
            try:
                result = future.result()
            except BrokenProcessPool as e:
                for other, j in futures.items():  # keep what finished before the break
                    if other.done() and not other.cancelled() and other.exception() is None:
                        results.put(j, other.result())
                return str(e) or type(e).__name__
            except Exception as e:  # fn raised, or an item or result did not pickle
                result = lost(items[i], f"{type(e).__name__}: {e}")
            results.put(i, result)
        return None


class _Results(dict[int, R]):
    """Results by item index: each one seen by ``each`` and counted by ``progress``."""

    def __init__(self, each: Each[R] | None, progress: ItemsDone | None) -> None:
        super().__init__()
        self.each, self.progress = each, progress

    def put(self, i: int, result: R) -> None:
        self[i] = result if self.each is None else self.each(i, result)
        if self.progress is not None:
            self.progress(len(self))

    def in_order(self, n: int) -> list[R]:
        return [self[i] for i in range(n)]


def _stop_now(pool: ProcessPoolExecutor) -> None:
    """On an interrupt: queued items never start, and the workers are killed, not waited
    for. A shutdown that waits can itself be cut by a second Ctrl-C, leaving a worker
    waiting for work that the exit then joins forever (with the CLI ignoring signals)."""
    workers = list((pool._processes or {}).values())  # the executor has no public handle
    pool.shutdown(wait=False, cancel_futures=True)
    for worker in workers:
        worker.kill()
