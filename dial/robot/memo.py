"""Solutions already found in this process, by their exact inputs (the IK's memo).

A solve depends only on its inputs (the solvers keep no state between calls that changes a
result), so a repeated problem gives back the very same array: the runs of a script in one
process (a sweep's trials, a notebook, a benchmark) solve the same targets, since locations
follow the *believed* object poses. Bounded, oldest first out. Kinematics keep their
solves here (:mod:`dial.backend.ik`); a planner keeps results built from solves, such as a
straight line's waypoints (:func:`recall`, :func:`remember`).
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np

Key = tuple[object, ...]


class Memo:
    """A bounded map from exact inputs to results."""

    SIZE = 50_000

    def __init__(self) -> None:
        self._values: OrderedDict[Key, object] = OrderedDict()

    def get(self, key: Key) -> object:
        return self._values.get(key)

    def clear(self) -> None:
        self._values.clear()

    def put(self, key: Key, value: object) -> None:
        self._values[key] = value
        if len(self._values) > self.SIZE:
            self._values.popitem(last=False)


SOLUTIONS = Memo()


def memo_key(kind: str, *parts: object) -> Key:
    """The key of a result of ``kind`` computed from ``parts`` (arrays by their bytes)."""
    return (
        kind,
        *(
            np.ascontiguousarray(p, dtype=np.float64).tobytes() if isinstance(p, np.ndarray) else p
            for p in parts
        ),
    )


def recall(kind: str, *parts: object) -> tuple[Key, object]:
    """The memo's key for a result computed from these exact inputs, and the result if one
    is known (else None): for results built from solves, such as a line's waypoints."""
    key = memo_key(kind, *parts)
    return key, SOLUTIONS.get(key)


def remember(key: Key, value: object) -> None:
    """Keep ``value`` under ``key`` (from :func:`recall`)."""
    SOLUTIONS.put(key, value)


def forget_solutions() -> None:
    """Empty the memo: the next solves cost what they cost in a fresh process (benchmarks)."""
    SOLUTIONS.clear()
