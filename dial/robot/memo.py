"""The IK's memo: solutions by their exact inputs, in this process and in the user's cache.

A solve depends only on its inputs (the solvers keep no state between calls that changes a
result), so a repeated problem gives back the very same array: the runs of a script solve
the same targets, since locations follow the *believed* object poses. In one process (a
sweep's trials, a notebook, a benchmark) the memo holds what was solved; across processes
its file in the user's cache folder does, so that a script run again starts without
loading mink, qpsolvers or SciPy (docs/architecture.md, "Start-up").

The file is named by a **fingerprint** of everything a solution depends on besides its
inputs (:mod:`dial.backend.fingerprint`: the compiled IK model, the solver's code, the
versions and files of what it runs on, the machine). Any change gives another file, so an
entry is never read where it could differ from a fresh solve. A process writes the file at exit
only if it solved something new (its own entries last; the oldest beyond :data:`MAX_SAVED`
dropped), by renaming a whole new file over it. The folder is ``$DIAL_CACHE``, else the
platform's user cache folder; ``DIAL_CACHE=off`` turns the file off. A folder that is
missing and cannot be made, is read-only or holds a damaged file is a cache miss, never an
error. Values are stored with :mod:`marshal` (bytes, floats and tuples only), as Python
stores its own bytecode cache.
"""

from __future__ import annotations

import atexit
import marshal
from collections import OrderedDict
from contextlib import suppress
from pathlib import Path

import numpy as np

from dial import usercache

MAX_SAVED = 20_000  # entries in one file (about 5 MB; read in about 10 ms)

Key = tuple[object, ...]
Stored = bytes | tuple[float, ...]  # an array's float64 bytes, or a failed solve's figures


def memo_key(kind: str, *parts: object) -> Key:
    """The key of a result computed from these exact inputs (arrays by their bytes)."""
    return (
        kind,
        *(
            np.ascontiguousarray(p, dtype=np.float64).tobytes() if isinstance(p, np.ndarray) else p
            for p in parts
        ),
    )


class Memo:
    """Results by key: this process's, then those of the file named ``fingerprint``.

    Bounded in memory (oldest first out). Arrays (float64, one axis) and tuples of floats
    are kept on disk too; anything else (a line's segment) only in this process.
    """

    SIZE = 50_000

    def __init__(self, fingerprint: str | None = None) -> None:
        self.fingerprint = fingerprint
        self._values: OrderedDict[Key, object] = OrderedDict()
        self._disk: dict[Key, Stored] | None = None  # read on the first miss
        self._used: dict[Key, Stored] = {}  # read from the file, or new, in this process
        self._new = False

    def get(self, key: Key) -> object:
        value = self._values.get(key)
        if value is not None or self.fingerprint is None:
            return value
        if self._disk is None:
            self._disk = _read(self.fingerprint)
        stored = self._disk.get(key)
        if stored is None or not _whole(stored):  # an entry as the memo writes one, or a miss
            return None
        self._used[key] = stored
        value = _decoded(stored)
        self._keep(key, value)
        return value

    def put(self, key: Key, value: object) -> None:
        self._keep(key, value)
        stored = _stored(key, value) if self.fingerprint is not None else None
        if stored is not None:
            self._used[key] = stored
            if not self._new:
                self._new = True
                _WRITERS.append(self)

    def clear(self) -> None:
        """Forget every result, and do not read the file again (a fresh, uncached process)."""
        self._values.clear()
        self._disk = {}
        self._used.clear()

    def save(self) -> None:
        """Merge this process's entries into the file, if it solved anything new."""
        if not self._new or self.fingerprint is None:
            return
        self._new = False
        folder = cache_dir()
        if folder is None:
            return
        old = _read(self.fingerprint)
        merged = {k: v for k, v in old.items() if k not in self._used and _kept(k, v)}
        merged.update(self._used)
        keep = dict(list(merged.items())[-MAX_SAVED:])
        with suppress(OSError, ValueError):
            usercache.replace(folder / f"{self.fingerprint}.marshal", marshal.dumps(keep))

    def _keep(self, key: Key, value: object) -> None:
        self._values[key] = value
        if len(self._values) > self.SIZE:
            self._values.popitem(last=False)


def _stored(key: Key, value: object) -> Stored | None:
    """``value`` as the file keeps it, or None if it stays in this process."""
    if not all(type(p) in (str, bytes, int, float, bool) for p in key):
        return None
    if isinstance(value, np.ndarray) and value.dtype == np.float64 and value.ndim == 1:
        return value.tobytes()
    if isinstance(value, tuple) and all(type(x) is float for x in value):
        return value
    return None


def _decoded(stored: Stored) -> object:
    if isinstance(stored, bytes):
        return np.frombuffer(stored, dtype=np.float64).copy()
    return stored


def cache_dir() -> Path | None:
    """The folder of the IK's files: ``$DIAL_CACHE/ik``, else in the user's cache folder;
    None when ``DIAL_CACHE`` turns it off (:mod:`dial.usercache`)."""
    return usercache.folder("ik")


def _read(fingerprint: str) -> dict[Key, Stored]:
    """The file's entries, as read: each is checked when it is used (:func:`_kept`), so that
    a file of 20,000 entries costs its reading alone."""
    folder = cache_dir()
    if folder is None:
        return {}
    try:
        found = marshal.loads((folder / f"{fingerprint}.marshal").read_bytes())
    except (OSError, EOFError, ValueError, TypeError):
        return {}  # none yet, unreadable or damaged: solve again
    return found if isinstance(found, dict) else {}


def _kept(key: object, value: object) -> bool:
    """Whether an entry of a file is as :meth:`Memo.save` writes one."""
    return isinstance(key, tuple) and _whole(value)


def _whole(value: object) -> bool:
    """Whether ``value`` is as :func:`_stored` writes one: whole float64s, or floats."""
    if isinstance(value, bytes):
        return len(value) % 8 == 0
    return isinstance(value, tuple) and all(type(x) is float for x in value)


_MEMOS: dict[str | None, Memo] = {}
_WRITERS: list[Memo] = []


def memo_for(name: str | None) -> Memo:
    """The memo kept in the file ``name`` (a fingerprint; None: in this process only), one
    per name in a process."""
    memo = _MEMOS.get(name)
    if memo is None:
        memo = _MEMOS[name] = Memo(name)
    return memo


SOLUTIONS = Memo(None)  # results built from solves (a line's waypoints): this process only


def recall(kind: str, *parts: object) -> tuple[Key, object]:
    """The memo's key for a result computed from these exact inputs, and the result if one
    is known (else None): for results built from solves, such as a line's waypoints."""
    key = memo_key(kind, *parts)
    return key, SOLUTIONS.get(key)


def remember(key: Key, value: object) -> None:
    """Keep ``value`` under ``key`` (from :func:`recall`)."""
    SOLUTIONS.put(key, value)


def forget_solutions() -> None:
    """Empty every memo, and read no file again in this process: the next solves cost what
    they cost in a fresh process without a cache (benchmarks)."""
    SOLUTIONS.clear()
    for memo in _MEMOS.values():
        memo.clear()


@atexit.register
def _save_all() -> None:
    for memo in _WRITERS:
        memo.save()
