"""A VAL-II subset for stored arm programs: MOVE, MOVES, APPRO, DEPART, DRIVE.

Keywords are case-insensitive; arguments are separated by spaces or commas, as in VAL-II;
``;`` starts a comment. Distances are metres unless suffixed (``100mm``); DRIVE angles are
degrees unless suffixed (``1.2rad``). Values are stored in SI (m, rad).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from dial.units import UnitError, parse_quantity

NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
VERBS: tuple[str, ...] = ("MOVE", "MOVES", "APPRO", "DEPART", "DRIVE")
MAX_APPROACH = 1.0  # m; farther than this is a typo, not an approach
MAX_DRIVE = 2.0 * math.pi  # rad; one full turn of a joint per statement


class StatementError(ValueError):
    """A program line that does not parse; the message says what was expected."""


@dataclass(frozen=True)
class Move:
    """``MOVE loc`` (joint-interpolated) or ``MOVES loc`` (straight line)."""

    line: int
    location: str
    straight: bool


@dataclass(frozen=True)
class Appro:
    """``APPRO loc D``: to ``distance`` m back along the tool z axis of ``loc`` (joint-interp.)."""

    line: int
    location: str
    distance: float


@dataclass(frozen=True)
class Depart:
    """``DEPART D``: ``distance`` m back along the current tool z axis (straight line)."""

    line: int
    distance: float


@dataclass(frozen=True)
class Drive:
    """``DRIVE J DEG``: turn arm joint ``joint`` (1-based) by ``angle`` rad, relative."""

    line: int
    joint: int
    angle: float


Statement = Move | Appro | Depart | Drive


@dataclass(frozen=True)
class Ex:
    """``EX PROG``: run the world file's stored program ``program`` (a command, not a
    statement of a stored program)."""

    program: str


_USAGE = {
    "MOVE": "MOVE LOCATION",
    "MOVES": "MOVES LOCATION",
    "APPRO": "APPRO LOCATION DISTANCE",
    "DEPART": "DEPART DISTANCE",
    "DRIVE": "DRIVE JOINT DEGREES",
}


def parse_statement(text: str, line: int = 1) -> Statement | None:
    """Parse one program line; ``None`` for a blank or comment-only line."""
    words = text.split(";", 1)[0].replace(",", " ").split()
    if not words:
        return None
    verb, args = words[0].upper(), words[1:]
    if verb not in VERBS:
        raise StatementError(f"unknown command '{words[0]}'; valid commands: {', '.join(VERBS)}")
    if len(args) != len(_USAGE[verb].split()) - 1:
        raise StatementError(f"expected '{_USAGE[verb]}', got '{' '.join(words)}'")
    if verb in ("MOVE", "MOVES"):
        return Move(line, _name(args[0]), straight=verb == "MOVES")
    if verb == "APPRO":
        return Appro(line, _name(args[0]), _length(args[1], 0.0, MAX_APPROACH))
    if verb == "DEPART":
        return Depart(line, _length(args[0], -MAX_APPROACH, MAX_APPROACH))
    return Drive(line, _joint(args[0]), _angle(args[1]))


def _name(text: str) -> str:
    if not NAME.match(text):
        raise StatementError(f"expected a location name ([A-Za-z_][A-Za-z0-9_]*), got '{text}'")
    return text


def _length(text: str, lo: float, hi: float) -> float:
    try:
        value = parse_quantity(text, "length", "m")
    except UnitError as e:
        raise StatementError(str(e)) from None
    if not lo <= value <= hi:
        raise StatementError(f"distance {text} is out of range: expected {lo:g} m to {hi:g} m")
    return value


def _joint(text: str) -> int:
    # The arm's own count is checked where the robot is known (a world file's, a session's).
    if len(text) != 1 or text not in "123456789":
        raise StatementError(f"expected an arm joint number from 1 to 9, got '{text}'")
    return int(text)


def _angle(text: str) -> float:
    try:
        value = parse_quantity(text, "angle", "deg")
    except UnitError as e:
        raise StatementError(str(e)) from None
    if abs(value) > MAX_DRIVE:
        raise StatementError(f"angle {text} is out of range: expected -360 deg to 360 deg")
    return value
