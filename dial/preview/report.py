"""The preview's findings: its problems, one line each, and what it previewed.

A problem is ``FILE:LINE:COL: EVENT: message``, at the run (the ``#`` of its execution
line) that causes it. A collision found again and again along one motion is one problem,
with the deepest overlap seen.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from dial.preview.places import Place
from dial.preview.scene import Hit


@dataclass
class _Entry:
    place: Place
    text: str
    depth: float | None  # a contact's deepest overlap (m); None for other problems
    context: str  # what the run was doing
    why: str  # on a path the preview does not take: why (then it is a note)

    def line(self) -> str:
        what = self.text
        if self.depth is not None:
            what += f", {self.depth * 1000:.1f} mm deep"
        if self.context:
            what += f" (in {self.context})"
        if self.why:
            return f"{self.place}: note: {self.place.event}: {what}; {self.why}"
        return f"{self.place}: {self.place.event}: {what}"


class Problems:
    """The problems found so far, in the order found, each once.

    One found on a path the preview does not take (the other branch of an ``@if``, a
    reaction whose monitor does not fire) is a *note*: what would go wrong if it were taken.
    """

    def __init__(self) -> None:
        self._items: dict[tuple[object, ...], _Entry] = {}

    def add(self, place: Place, message: str, why: str = "") -> None:
        self._put((place, message), _Entry(place, message, None, "", why))

    def hit(self, place: Place, hit: Hit, context: str, why: str = "") -> None:
        entry = self._put((place, hit.key), _Entry(place, hit.text, hit.depth, context, why))
        if entry.depth is not None and hit.depth > entry.depth:
            entry.depth, entry.text = hit.depth, hit.text  # the deepest pair tells

    def _put(self, key: tuple[object, ...], entry: _Entry) -> _Entry:
        found = self._items.setdefault(key, entry)
        if not entry.why:
            found.why = ""  # also found on the path taken: a problem
        return found

    def __len__(self) -> int:
        return len(self._items)

    def lines(self) -> list[str]:
        """The problems, then the notes."""
        entries = list(self._items.values())
        return [e.line() for e in entries if not e.why] + [e.line() for e in entries if e.why]

    @property
    def count(self) -> int:
        return sum(not e.why for e in self._items.values())


@dataclass
class Counts:
    """What the preview went through."""

    blocks: int = 0
    arm: int = 0  # arm targets: program statements, VAL-II commands, arm moves, guarded moves
    hand: int = 0  # hand targets: poses, finger moves, grasps, finger guarded moves
    branches: int = 0  # @if, each previewed both ways
    reactions: int = 0  # @on bodies
    loops: int = 0  # @repeat bodies, each previewed once


@dataclass
class PreviewResult:
    """``dial preview``'s result: the problems as lines, and what was previewed."""

    path: str
    problems: list[str]  # FILE:LINE:COL: EVENT: message
    notes: list[str]  # problems on paths the preview does not take
    counts: Counts
    panels: int = 0

    @property
    def ok(self) -> bool:
        return not self.problems

    def summary(self) -> str:
        """One line: ``pour.dial: preview OK, 1 block, 9 arm targets, 6 hand targets``..."""
        c = self.counts
        head = "preview OK" if self.ok else _n(len(self.problems), "problem")
        parts = [_n(c.blocks, "block"), _n(c.arm, "arm target"), _n(c.hand, "hand target")]
        also = [
            f"both ways of {_n(c.branches, '@if')}" if c.branches else "",
            _n(c.reactions, "@on reaction") if c.reactions else "",
            f"{_n(c.loops, 'loop')} once each" if c.loops else "",
        ]
        also = [a for a in also if a]
        tail = f" ({', '.join(also)})" if also else ""
        notes = f"; {_n(len(self.notes), 'note')} on paths not taken" if self.notes else ""
        return f"{Path(self.path).name}: {head}: {', '.join(parts)}{tail}{notes}"


def _n(count: int, what: str) -> str:
    return f"{count} {what}{'' if count == 1 else 's'}"
