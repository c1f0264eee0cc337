"""Typed access to a parsed TOML table, with errors that name the file and the key."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from dial.errors import DialError
from dial.robots.fields import key_problems, value_kind


class WorldFileError(DialError, ValueError):
    """A world file (or the hand-pose file it uses) is malformed.

    The message starts with ``PATH: KEY:`` and, for programs, the program line.
    """

    def __init__(self, path: Path | str, key: str, message: str) -> None:
        self.path = str(path)
        self.key = key
        self.problem = message
        where = f"{self.path}: {key}: " if key else f"{self.path}: "
        super().__init__(where + message)

    def __reduce__(self) -> tuple[type[WorldFileError], tuple[str, str, str]]:
        # Pickled (a worker process's error) as what it was made from, not its message.
        return type(self), (self.path, self.key, self.problem)


class Reader:
    """Reads values out of one file's TOML data; every failure raises :class:`WorldFileError`."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def error(self, key: str, message: str) -> WorldFileError:
        return WorldFileError(self.path, key, message)

    def table(self, value: Any, key: str) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            raise self.error(key, f"expected a table, got {value_kind(value)}")
        return value

    def keys(
        self, table: Mapping[str, Any], key: str, required: Iterable[str], optional: Iterable[str]
    ) -> None:
        """Reject missing and unknown keys, listing the valid ones."""
        for name, message in key_problems(table, required, optional):
            raise self.error(key if name is None else _join(key, name), message)

    def string(self, value: Any, key: str) -> str:
        if not isinstance(value, str):
            raise self.error(key, f"expected a string, got {value_kind(value)}")
        return value

    def choice(self, value: Any, key: str, choices: Iterable[str], what: str) -> str:
        text = self.string(value, key)
        choices = tuple(choices)
        if text not in choices:
            raise self.error(key, f"unknown {what} '{text}'; valid: {', '.join(choices)}")
        return text

    def number(self, value: Any, key: str) -> float:
        # bool is an int subclass; true/false is never a number here.
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(key, f"expected a number, got {value_kind(value)}")
        if not math.isfinite(value):
            raise self.error(key, f"expected a finite number, got {value}")
        return float(value)

    def integer(self, value: Any, key: str) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, f"expected a whole number, got {value_kind(value)}")
        return value

    def vector(self, value: Any, key: str, n: int) -> tuple[float, ...]:
        if not isinstance(value, list) or len(value) != n:
            raise self.error(key, f"expected a list of {n} numbers, got {value_kind(value)}")
        return tuple(self.number(v, f"{key}[{i}]") for i, v in enumerate(value))

    def strings(self, value: Any, key: str) -> tuple[str, ...]:
        if not isinstance(value, list) or not value:
            raise self.error(key, f"expected a non-empty list of strings, got {value_kind(value)}")
        return tuple(self.string(v, f"{key}[{i}]") for i, v in enumerate(value))


def _join(key: str, name: str) -> str:
    return f"{key}.{name}" if key else name
