"""The compiled timeline: every run with its block, start tick, executing and held ticks.

Ticks here are block ticks (1-based). :func:`expand` lays the whole script out
on absolute ticks for display, expanding counted repeats and calls.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

from dial.errors import Span
from dial.parser.ast import Condition

if TYPE_CHECKING:
    from dial.parser.check import Script


@dataclass(frozen=True)
class Run:
    """One run of an event inside a block.

    The run executes in ticks ``start..exec_end`` and is held (its effectors
    keep the final command, still reserved) in ``exec_end+1..hold_end``.
    """

    event: str
    line: int
    start: int
    exec_end: int
    hold_end: int
    effectors: frozenset[str]
    span: Span = field(default=Span(0, 0, 0), compare=False)  # the run's marks in the diagram

    @property
    def executing(self) -> range:
        return range(self.start, self.exec_end + 1)

    @property
    def held(self) -> range:
        return range(self.exec_end + 1, self.hold_end + 1)


@dataclass(frozen=True)
class Watch:
    """A watched span: ``event`` sensed every control period of block ticks start..end."""

    event: str
    line: int
    start: int
    end: int
    span: Span = field(default=Span(0, 0, 0), compare=False)


@dataclass(frozen=True)
class TBlock:
    line: int
    length: int
    runs: tuple[Run, ...]  # ordered by start tick, then line: the order runs start in
    watches: tuple[Watch, ...] = ()  # in (start, line) order
    reactions: tuple[TOn, ...] = ()  # in file order


@dataclass(frozen=True)
class TOn:
    """``@on COND`` ... ``@end``: the reaction to a monitor of the block it follows."""

    condition: Condition
    body: tuple[Step, ...]
    line: int


@dataclass(frozen=True)
class TResume:
    line: int


@dataclass(frozen=True)
class TRetry:
    max: int
    line: int


@dataclass(frozen=True)
class TAbort:
    message: str
    line: int


@dataclass(frozen=True)
class TRepeat:
    kind: Literal["count", "until", "while"]
    count: int  # the repeat count, or the loop limit ("max") of until/while
    condition: Condition | None
    body: tuple[Step, ...]
    line: int


@dataclass(frozen=True)
class TIf:
    condition: Condition
    then: tuple[Step, ...]
    orelse: tuple[Step, ...]
    line: int


@dataclass(frozen=True)
class TCall:
    target: str
    script: Script
    line: int


Step = TBlock | TRepeat | TIf | TCall | TResume | TRetry | TAbort


@dataclass(frozen=True)
class Section:
    """A stretch of absolute ticks and what it comes from, for display."""

    first: int
    last: int
    label: str
    path: str
    line: int


@dataclass(frozen=True)
class Placed:
    """A run placed on absolute ticks."""

    run: Run
    offset: int  # absolute tick of the block's tick 1, minus one
    path: str

    @property
    def start(self) -> int:
        return self.offset + self.run.start

    @property
    def exec_end(self) -> int:
        return self.offset + self.run.exec_end

    @property
    def hold_end(self) -> int:
        return self.offset + self.run.hold_end


@dataclass(frozen=True)
class Layout:
    runs: tuple[Placed, ...]
    sections: tuple[Section, ...]
    length: int


def expand(script: Script) -> Layout:
    """Lay ``script`` out on absolute ticks.

    Counted repeats are expanded; an until/while loop is laid out once and
    labelled as a loop; both branches of an ``@if`` start at the same tick
    (the longer one sets where the script goes on); calls are inlined.
    """
    runs: list[Placed] = []
    sections: list[Section] = []

    def walk(steps: tuple[Step, ...], offset: int, path: str, label: str) -> int:
        for step in steps:
            if isinstance(step, TBlock):
                runs.extend(Placed(r, offset, path) for r in step.runs)
                sections.append(
                    Section(offset + 1, offset + step.length, label or "block", path, step.line)
                )
                offset += step.length
            elif isinstance(step, TRepeat):
                prefix = f"{label} " if label else ""
                if step.kind == "count":
                    for i in range(step.count):
                        tag = f"{prefix}@repeat {step.count} ({i + 1}/{step.count})"
                        offset = walk(step.body, offset, path, tag)
                else:
                    tag = f"{prefix}@repeat {step.kind} {step.condition} (loop, max {step.count})"
                    offset = walk(step.body, offset, path, tag)
            elif isinstance(step, TIf):
                prefix = f"{label} " if label else ""
                then_end = walk(step.then, offset, path, f"{prefix}@if {step.condition}")
                else_end = walk(step.orelse, offset, path, f"{prefix}@else ({step.condition})")
                offset = max(then_end, else_end)
            elif isinstance(step, TCall):
                prefix = f"{label} " if label else ""
                offset = walk(
                    step.script.timeline, offset, step.script.path, f"{prefix}@call {step.target}"
                )
        return offset

    length = walk(script.timeline, 0, script.path, "")
    return Layout(tuple(runs), tuple(sections), length)


def iter_blocks(steps: tuple[Step, ...]) -> Iterator[TBlock]:
    """Every block of ``steps``, in file order (not into calls)."""
    for step in steps:
        if isinstance(step, TBlock):
            yield step
        elif isinstance(step, TRepeat):
            yield from iter_blocks(step.body)
        elif isinstance(step, TIf):
            yield from iter_blocks(step.then)
            yield from iter_blocks(step.orelse)
