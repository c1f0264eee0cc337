"""Faults on purpose (DESIGN 2.8): the ``--disturb SPEC`` grammar, pure Python.

``push body=NAME force=FX,FY,FZ at=T for=D``: a world-frame force (N) on a body from
simulated time T (s from the first tick) for D s. ``sense sensor=KIND:FINGER at=T
[for=D]``: that sensor of a finger reads as untouched from T, for D s or to the end.
Whether NAME is a body of the scene is checked when the scene is loaded, before anything
moves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from dial.errors import OptionError
from dial.instructions.types import CONTACT_KINDS, FINGERS
from dial.units import UnitError, parse_quantity

PUSH_FORM = "push body=NAME force=FX,FY,FZ at=T for=D"
SENSE_FORM = "sense sensor=KIND:FINGER at=T [for=D]"
MAX_FORCE = 1000.0  # N: a push beyond it is a typo, not a test


class DisturbanceError(OptionError):
    """A ``--disturb`` SPEC that does not parse, or names no body of the scene: a usage
    error; the message says what was expected."""


@dataclass(frozen=True)
class Push:
    """A constant world-frame force on a body over a time window."""

    body: str
    force: tuple[float, float, float]  # N, world frame
    at: float  # s from the first tick
    duration: float  # s
    text: str

    @property
    def until(self) -> float | None:
        return self.at + self.duration


@dataclass(frozen=True)
class Dropout:
    """A sensor of one finger reads as untouched (no contact) over a time window."""

    sensor: str  # tactile, force or position
    finger: int
    at: float
    duration: float | None  # None: to the end of the run
    text: str

    @property
    def until(self) -> float | None:
        return None if self.duration is None else self.at + self.duration


Disturbance = Push | Dropout


def _fields(text: str, form: str, words: list[str]) -> dict[str, str]:
    fields: dict[str, str] = {}
    for word in words:
        key, eq, value = word.partition("=")
        if not eq or not value:
            raise DisturbanceError(f"--disturb '{text}': expected key=value, got '{word}' ({form})")
        if key in fields:
            raise DisturbanceError(f"--disturb '{text}': '{key}=' is given twice ({form})")
        fields[key] = value
    return fields


def _time(text: str, form: str, key: str, value: str, positive: bool) -> float:
    try:
        seconds = parse_quantity(value, "time", "s")
    except UnitError as e:
        raise DisturbanceError(f"--disturb '{text}': {key}={value}: {e} ({form})") from None
    if seconds < 0 or (positive and seconds == 0):
        least = "above 0 s" if positive else "0 s or more"
        raise DisturbanceError(f"--disturb '{text}': {key}= must be {least}, got {value}")
    return seconds


def _force(text: str, value: str) -> tuple[float, float, float]:
    parts = value.split(",")
    try:
        if len(parts) != 3:
            raise UnitError(f"expected three components FX,FY,FZ, got '{value}'")
        fx, fy, fz = (parse_quantity(p, "force", "N") for p in parts)
    except UnitError as e:
        raise DisturbanceError(f"--disturb '{text}': force={value}: {e} ({PUSH_FORM})") from None
    if math.sqrt(fx * fx + fy * fy + fz * fz) > MAX_FORCE:
        raise DisturbanceError(
            f"--disturb '{text}': force={value} is above {MAX_FORCE:g} N in magnitude"
        )
    return fx, fy, fz


def _check_keys(text: str, form: str, fields: dict[str, str], required: set[str]) -> None:
    allowed = {w.split("=")[0].strip("[]") for w in form.split()[1:]}
    unknown = sorted(set(fields) - allowed)
    if unknown:
        raise DisturbanceError(f"--disturb '{text}': unknown key '{unknown[0]}='; expected {form}")
    missing = sorted(required - set(fields))
    if missing:
        raise DisturbanceError(f"--disturb '{text}': missing {missing[0]}=; expected {form}")


def parse_disturbance(text: str) -> Disturbance:
    """Parse one ``--disturb`` SPEC; raise :class:`DisturbanceError` saying what was expected."""
    words = text.split()
    if not words or words[0] not in ("push", "sense"):
        got = f"'{words[0]}'" if words else "nothing"
        raise DisturbanceError(
            f"--disturb '{text}': expected 'push' or 'sense', got {got} "
            f"(forms: {PUSH_FORM} | {SENSE_FORM})"
        )
    if words[0] == "push":
        fields = _fields(text, PUSH_FORM, words[1:])
        _check_keys(text, PUSH_FORM, fields, {"body", "force", "at", "for"})
        return Push(
            fields["body"],
            _force(text, fields["force"]),
            _time(text, PUSH_FORM, "at", fields["at"], positive=False),
            _time(text, PUSH_FORM, "for", fields["for"], positive=True),
            text,
        )
    fields = _fields(text, SENSE_FORM, words[1:])
    _check_keys(text, SENSE_FORM, fields, {"sensor", "at"})
    kind, colon, finger = fields["sensor"].partition(":")
    if kind not in CONTACT_KINDS or not colon or finger not in FINGERS:
        raise DisturbanceError(
            f"--disturb '{text}': sensor={fields['sensor']}: expected KIND:FINGER with KIND "
            f"one of {', '.join(CONTACT_KINDS)} and FINGER one of {', '.join(FINGERS)}"
        )
    duration = fields.get("for")
    return Dropout(
        kind,
        FINGERS.index(finger),
        _time(text, SENSE_FORM, "at", fields["at"], positive=False),
        None if duration is None else _time(text, SENSE_FORM, "for", duration, positive=True),
        text,
    )
