"""Quantities with unit suffixes: ``10deg``, ``5mm``, ``2N``, ``300ms``.

Values are converted to SI (m, rad, N, s). A bare number is read in the
parameter's default unit, which is SI unless the instruction says otherwise
(``drive J DEG`` takes degrees).
"""

from __future__ import annotations

import math
import re
from typing import Literal

from dial.errors import shorten

Dimension = Literal["length", "angle", "force", "time", "speed", "angular_speed"]

UNITS: dict[Dimension, dict[str, float]] = {
    "length": {"m": 1.0, "cm": 0.01, "mm": 0.001},
    "angle": {"rad": 1.0, "deg": math.pi / 180.0},
    "force": {"N": 1.0, "mN": 0.001},
    "time": {"s": 1.0, "ms": 0.001},
    "speed": {"m/s": 1.0, "mm/s": 0.001},
    "angular_speed": {"rad/s": 1.0, "deg/s": math.pi / 180.0},
}

NOUNS: dict[Dimension, str] = {
    "length": "a length",
    "angle": "an angle",
    "force": "a force",
    "time": "a duration",
    "speed": "a speed",
    "angular_speed": "an angular speed",
}

# ASCII digits only: int() and float() also take other scripts' digits, which a script's
# reader would not recognise as numbers.
_NUMBER = re.compile(r"^([+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)([A-Za-z/]*)$")
MAX_NUMBER_CHARS = 40  # longer than any number a script needs; keeps messages and parsing small


class UnitError(ValueError):
    """A quantity that does not parse; the message says what was expected."""


def expected(dim: Dimension, default_unit: str) -> str:
    """Human description such as ``a length in m (or cm, mm)``."""
    others = [u for u in UNITS[dim] if u != default_unit]
    return f"{NOUNS[dim]} in {default_unit} (or {', '.join(others)})"


def parse_number(text: str) -> float:
    """A plain finite number, no unit."""
    m = _NUMBER.match(text) if len(text) <= MAX_NUMBER_CHARS else None
    if m is None or m.group(2):
        raise UnitError(f"expected a number, got '{shorten(text)}'")
    value = float(m.group(1))
    if not math.isfinite(value):
        raise UnitError(f"expected a finite number, got '{text}'")
    return value


def parse_quantity(text: str, dim: Dimension, default_unit: str) -> float:
    """Parse ``text`` as a quantity of ``dim``; return it in SI units."""
    m = _NUMBER.match(text) if len(text) <= MAX_NUMBER_CHARS else None
    if m is None:
        raise UnitError(f"expected {expected(dim, default_unit)}, got '{shorten(text)}'")
    number, unit = m.group(1), m.group(2) or default_unit
    scale = UNITS[dim].get(unit)
    if scale is None:
        raise UnitError(
            f"unit '{unit}' is not {NOUNS[dim]} unit; expected {expected(dim, default_unit)}"
        )
    value = float(number) * scale
    if not math.isfinite(value):
        raise UnitError(f"expected a finite number, got '{text}'")
    return value


def format_quantity(value: float, dim: Dimension, unit: str) -> str:
    """Render an SI value in ``unit``, compactly: ``format_quantity(0.005, 'length', 'mm')``."""
    return f"{value / UNITS[dim][unit]:g} {unit}"
