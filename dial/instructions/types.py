"""Parameter types of the instruction catalogue.

Each type turns one written word into a value, or raises :class:`ParamError`
with a message that says what was expected (with units and valid choices).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Generic, Literal, NamedTuple, TypeVar

from dial.errors import shorten
from dial.units import Dimension, UnitError, expected, format_quantity, parse_number, parse_quantity

FINGERS: tuple[str, ...] = ("index", "middle", "ring", "thumb")
ARM = "arm"
EFFECTORS: tuple[str, ...] = (ARM, *FINGERS)
ALL_JOINTS = 0xFFFF
ContactKind = Literal["tactile", "force", "position"]
CONTACT_KINDS: tuple[ContactKind, ...] = ("tactile", "force", "position")
# Threshold dimension and default of each contact kind (SI).
CONTACT_THRESHOLDS: dict[str, tuple[Dimension, str, float]] = {
    "tactile": ("length", "mm", 0.0001),  # taxel penetration depth
    "force": ("force", "N", 0.5),
    "position": ("length", "mm", 0.003),
}
NameKind = Literal["pose", "location", "program", "set", "object"]
T_co = TypeVar("T_co", covariant=True)


class Contact(NamedTuple):
    """A contact condition: it holds when finger ``finger``'s ``kind`` reading reaches
    ``threshold`` (m for tactile and position, N for force). See
    :mod:`dial.robot.contact`."""

    kind: ContactKind
    finger: int
    threshold: float


class ParamError(ValueError):
    """A word that is not a valid value for its parameter."""


class ParamType(Generic[T_co]):
    """Base of the parameter types: each parses a word into a ``T_co``; ``expected`` reads
    as 'expected <...>'."""

    expected: str = "a value"

    def parse(self, text: str) -> T_co:
        raise NotImplementedError


@dataclass(frozen=True)
class Quantity(ParamType[float]):
    dim: Dimension
    unit: str
    lo: float
    hi: float
    lo_open: bool = False  # lo itself is excluded (e.g. a force above 0 N)

    @property
    def expected(self) -> str:  # type: ignore[override]
        return expected(self.dim, self.unit)

    def parse(self, text: str) -> float:
        try:
            value = parse_quantity(text, self.dim, self.unit)
        except UnitError as e:
            raise ParamError(str(e)) from None
        if value < self.lo or value > self.hi or (self.lo_open and value == self.lo):
            low = "above" if self.lo_open else "from"
            raise ParamError(
                f"{text} is out of range: expected {self.expected}, "
                f"{low} {format_quantity(self.lo, self.dim, self.unit)} "
                f"to {format_quantity(self.hi, self.dim, self.unit)}"
            )
        return value


@dataclass(frozen=True)
class Integer(ParamType[int]):
    lo: int
    hi: int

    @property
    def expected(self) -> str:  # type: ignore[override]
        return f"a whole number from {self.lo} to {self.hi}"

    def parse(self, text: str) -> int:
        try:
            value = parse_number(text)
        except UnitError:
            raise ParamError(f"expected {self.expected}, got '{text}'") from None
        if value != int(value) or not self.lo <= value <= self.hi:
            raise ParamError(f"expected {self.expected}, got '{text}'")
        return int(value)


_MASK = re.compile(r"^(0[xX][0-9A-Fa-f_]+|[0-9]+)$")  # ASCII digits only
MAX_MASK_CHARS = 24  # 0x plus 16 bits in hex with underscores, or decimal, with room


def parse_mask(text: str) -> int:
    """A 16-bit joint mask, hex (``0x0666``) or decimal; never empty."""
    if len(text) > MAX_MASK_CHARS or not _MASK.match(text):
        raise ParamError(f"expected a 16-bit joint mask such as 0x0666, got '{shorten(text)}'")
    digits = text.replace("_", "")
    hexa = digits[:2] in ("0x", "0X")
    if hexa and len(digits) == 2:  # only underscores after 0x
        raise ParamError(f"expected a 16-bit joint mask such as 0x0666, got '{text}'")
    value = int(digits[2:], 16) if hexa else int(digits, 10)  # 00666 is decimal 666
    if value > ALL_JOINTS:
        raise ParamError(f"joint mask {text} has bits above bit 15; masks are 16 bits (0xFFFF)")
    if value == 0:
        raise ParamError(f"joint mask {text} selects no joint")
    return value


class Mask(ParamType[int]):
    expected = "a 16-bit joint mask (bit 4*finger + joint), e.g. 0x000F"

    def parse(self, text: str) -> int:
        return parse_mask(text)


class MaskPair(ParamType[tuple[int, int]]):
    expected = "JMASK_TMASK: joint mask and tendon mask, e.g. 0x0666_0x0222"

    def parse(self, text: str) -> tuple[int, int]:
        parts = text.split("_", 1) if text.count("_") == 1 else text.split("_0x", 1)
        if len(parts) != 2 or not parts[0] or not parts[1]:
            raise ParamError(f"expected {self.expected}, got '{text}'")
        jmask = parse_mask(parts[0])
        tmask = parse_mask(parts[1] if parts[1].lower().startswith("0x") else "0x" + parts[1])
        if tmask & ~jmask:
            raise ParamError(
                f"tendon mask 0x{tmask:04X} monitors joints outside joint mask 0x{jmask:04X}"
            )
        return jmask, tmask


class Finger(ParamType[int]):
    expected = "a finger: index, middle, ring or thumb (or 0-3)"

    def parse(self, text: str) -> int:
        if text in FINGERS:
            return FINGERS.index(text)
        if text in ("0", "1", "2", "3"):
            return int(text)
        raise ParamError(f"expected {self.expected}, got '{text}'")


@dataclass(frozen=True)
class Choice(ParamType[T_co]):
    """One of a few words, each standing for itself (a ``Literal`` of them)."""

    values: tuple[T_co, ...]

    @property
    def expected(self) -> str:  # type: ignore[override]
        return "one of " + ", ".join(map(str, self.values))

    def parse(self, text: str) -> T_co:
        for value in self.values:
            if value == text:
                return value
        raise ParamError(f"expected {self.expected}, got '{text}'")


_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


@dataclass(frozen=True)
class Name(ParamType[str]):
    """A name looked up elsewhere: a pose, location, program or object of the scene, or a
    point set. ``anchored``: a location must be relative to an object (``locate``)."""

    kind: NameKind
    anchored: bool = False

    @property
    def expected(self) -> str:  # type: ignore[override]
        return f"a {self.kind} name"

    def parse(self, text: str) -> str:
        if not _NAME.match(text):
            raise ParamError(f"expected {self.expected} ([A-Za-z_][A-Za-z0-9_]*), got '{text}'")
        return text


@dataclass(frozen=True)
class Names(ParamType[tuple[str, ...]]):
    """Comma-separated names of one kind, each at most once (``lid,pitcher``)."""

    kind: NameKind

    @property
    def expected(self) -> str:  # type: ignore[override]
        return f"{self.kind} names separated by commas"

    def parse(self, text: str) -> tuple[str, ...]:
        names = tuple(text.split(","))
        for name in names:
            if not _NAME.match(name):
                raise ParamError(
                    f"expected {self.expected} ([A-Za-z_][A-Za-z0-9_]*), got '{shorten(text)}'"
                )
        twice = next((n for k, n in enumerate(names) if n in names[:k]), None)
        if twice is not None:
            raise ParamError(f"{self.kind} '{twice}' is given twice")
        return names


class Conditions(ParamType[tuple[tuple[ContactKind, float], ...]]):
    """``tactile[:0.2mm],force[:1N],position[:3mm]``: contact conditions, any one ends the move."""

    expected = "contact conditions KIND[:THRESHOLD],... with KIND tactile, force or position"

    def parse(self, text: str) -> tuple[tuple[ContactKind, float], ...]:
        out: list[tuple[ContactKind, float]] = []
        for item in text.split(","):
            written, _, threshold = item.partition(":")
            kind = next((k for k in CONTACT_KINDS if k == written), None)
            if kind is None:
                raise ParamError(f"expected {self.expected}, got '{item}'")
            if any(k == kind for k, _ in out):
                raise ParamError(f"contact condition '{kind}' is given twice")
            dim, unit, default = CONTACT_THRESHOLDS[kind]
            value = default
            if threshold:
                value = Quantity(dim, unit, 0.0, 1000.0, lo_open=True).parse(threshold)
            out.append((kind, value))
        return tuple(out)


def mask_fingers(mask: int) -> frozenset[str]:
    """The fingers that have at least one joint in ``mask``."""
    return frozenset(f for i, f in enumerate(FINGERS) if (mask >> (4 * i)) & 0xF)
