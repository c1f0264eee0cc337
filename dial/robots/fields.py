"""Typed reading of a parsed ``robot.toml``, collecting every problem at its key path.

A problem is kept with the key path it is about (``("fingers", 0, "joints", 2)``), so that the
caller can place it at its line and column (:mod:`dial.robots.locate`) and report them all.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from dial.robots.locate import Path


@dataclass(frozen=True)
class Problem:
    """One thing wrong in a robot profile: where (a key path) and what was expected."""

    path: Path
    message: str

    @property
    def key(self) -> str:
        """The path as written in TOML terms: ``fingers[0].joints[2]``."""
        out = ""
        for part in self.path:
            out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else part)
        return out


class Invalid(Exception):
    """A value that cannot be read; its problem is already recorded."""


class Fields:
    """Reads values; each failure records a :class:`Problem` and raises :class:`Invalid`.

    A value of None is a missing key, which :meth:`keys` has recorded already: reading it
    raises :class:`Invalid` without a second problem.
    """

    def __init__(self) -> None:
        self.problems: list[Problem] = []

    def fail(self, path: Path, message: str) -> Invalid:
        self.problems.append(Problem(path, message))
        return Invalid(message)

    def table(self, data: Mapping[str, Any], path: Path, name: str) -> Mapping[str, Any]:
        if name not in data:
            raise self.fail(path, f"missing table [{_join(path, name)}]")
        value = data[name]
        if not isinstance(value, Mapping):
            raise self.fail((*path, name), f"expected a table, got {value_kind(value)}")
        return value

    def keys(
        self, data: Mapping[str, Any], path: Path, required: Iterable[str], optional: Iterable[str]
    ) -> None:
        """Record missing and unknown keys (every one), listing the valid keys."""
        for name, message in key_problems(data, required, optional):
            self.problems.append(Problem(path if name is None else (*path, name), message))

    def string(self, value: Any, path: Path) -> str:
        _present(value)
        if not isinstance(value, str) or not value:
            raise self.fail(path, f"expected a name (a non-empty string), got {value_kind(value)}")
        return value

    def choice(self, value: Any, path: Path, choices: tuple[str, ...]) -> str:
        text = self.string(value, path)
        if text not in choices:
            raise self.fail(path, f"expected one of {', '.join(choices)}, got '{text}'")
        return text

    def number(
        self, value: Any, path: Path, positive: bool = False, nonnegative: bool = False
    ) -> float:
        _present(value)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(path, f"expected a number, got {value_kind(value)}")
        if not math.isfinite(value) or (positive and value <= 0) or (nonnegative and value < 0):
            what = (
                "a positive number"
                if positive
                else "a number of 0 or more"
                if nonnegative
                else "a finite number"
            )
            raise self.fail(path, f"expected {what}, got {value}")
        return float(value)

    def integer(self, value: Any, path: Path) -> int:
        _present(value)
        if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
            raise self.fail(path, f"expected a whole number above 0, got {value_kind(value)}")
        return value

    def names(self, value: Any, path: Path, n: int | None = None) -> tuple[str, ...]:
        """A list of names (of ``n`` of them, when given)."""
        items = self._list(value, path, n, "names")
        return tuple(self.string(v, (*path, i)) for i, v in enumerate(items))

    def numbers(
        self, value: Any, path: Path, n: int | None = None, positive: bool = False
    ) -> tuple[float, ...]:
        """A list of numbers (of ``n`` of them, when given)."""
        items = self._list(value, path, n, "numbers")
        return tuple(self.number(v, (*path, i), positive) for i, v in enumerate(items))

    def integers(self, value: Any, path: Path, n: int) -> tuple[int, ...]:
        """A list of ``n`` whole numbers above 0."""
        items = self._list(value, path, n, "whole numbers")
        return tuple(self.integer(v, (*path, i)) for i, v in enumerate(items))

    def per_joint(self, value: Any, path: Path, n: int, zero: bool = False) -> tuple[float, ...]:
        """A positive number (or 0, if ``zero``) for every one of ``n`` joints, or one number
        for all of them."""
        if isinstance(value, list):
            items = self._list(value, path, n, "numbers")
            return tuple(self.number(v, (*path, i), not zero, zero) for i, v in enumerate(items))
        _present(value)
        return (self.number(value, path, not zero, zero),) * n

    def _list(self, value: Any, path: Path, n: int | None, what: str) -> list[Any]:
        _present(value)
        if not isinstance(value, list) or not value:
            raise self.fail(path, f"expected a list of {what}, got {value_kind(value)}")
        if n is not None and len(value) != n:
            raise self.fail(path, f"expected {n} {what}, got {len(value)}")
        return value


def key_problems(
    table: Mapping[str, Any], required: Iterable[str], optional: Iterable[str]
) -> list[tuple[str | None, str]]:
    """Each missing key (None: the table's own problem) and each unknown key (its name), with
    a message listing the valid keys: missing ones first, in the order of ``required``."""
    required, optional = tuple(required), tuple(optional)
    valid = ", ".join((*required, *optional))
    missing = [(None, f"missing key '{n}' (keys: {valid})") for n in required if n not in table]
    unknown = [
        (name, f"unknown key; valid keys: {valid}")
        for name in table
        if name not in required and name not in optional
    ]
    return [*missing, *unknown]


def _present(value: Any) -> None:
    if value is None:
        raise Invalid("missing")


def _join(path: Path, name: str) -> str:
    return ".".join(str(p) for p in (*path, name))


def value_kind(value: Any) -> str:
    """What a TOML value is, for a message: "a string ('x')", "a list of 3", "a table"."""
    if isinstance(value, bool):
        return f"a boolean ({str(value).lower()})"
    if isinstance(value, str):
        return f"a string ('{value}')" if value else "an empty string"
    if isinstance(value, int | float):
        return f"a number ({value})"
    if isinstance(value, list):
        return f"a list of {len(value)}"
    if isinstance(value, Mapping):
        return "a table"
    return type(value).__name__
