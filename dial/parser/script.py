"""The compiled program: bound events and the timeline of blocks, loops, branches and calls.

Ticks here are block ticks (1-based). These are the types the runner executes; the
checker (:mod:`dial.parser.check`) builds them, :mod:`dial.parser.compile` lays out the
timeline.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Literal

from dial.errors import Span
from dial.instructions.base import Args, Instruction
from dial.instructions.scene_names import SceneNames
from dial.instructions.types import Contact
from dial.parser.ast import Condition, Definition, Program


@dataclass(frozen=True)
class EventDef:
    """A defined event bound to its instruction: its typed argument record (SI units; the
    instruction's module declares it) and the effectors it commands in its scene."""

    name: str
    instruction: Instruction
    args: Args
    effectors: frozenset[str]
    definition: Definition


@dataclass(frozen=True, slots=True)
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
    """A watched span: sensing event ``event``, whose condition is ``contact``, sensed at
    every physics step of block ticks start..end."""

    event: str
    line: int
    start: int
    end: int
    contact: Contact
    span: Span = field(default=Span(0, 0, 0), compare=False)


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


@dataclass(frozen=True, slots=True)
class TBlock:
    line: int
    length: int  # ticks, counting watched ones
    runs: tuple[Run, ...]  # ordered by start tick, then line: the order runs start in
    watches: tuple[Watch, ...] = ()  # in (start, line) order
    reactions: tuple[TOn, ...] = ()  # in file order: the first that fires in a period wins


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
class Script:
    """A checked script: its program, bound events and compiled timeline."""

    path: str
    program: Program
    events: Mapping[str, EventDef]
    condition_only: frozenset[str]
    timeline: tuple[Step, ...]
    scene: SceneNames | None
    # ``dial run --scene``: the scene that replaces ``@scene`` here and in every called script
    # (an absolute path or a bundled name), or None to use ``@scene``.
    scene_override: str | None = None

    @property
    def tick(self) -> float | None:
        return self.program.tick


def scripts_of(top: Script) -> list[Script]:
    """``top`` and every script it calls, directly or through others, each once (by path)."""
    found: dict[str, Script] = {}
    todo = [top]
    while todo:
        script = todo.pop()
        if script.path not in found:
            found[script.path] = script
            todo += [s.script for s in iter_steps(script.timeline) if isinstance(s, TCall)]
    return list(found.values())


def iter_steps(steps: tuple[Step, ...]) -> Iterator[Step]:
    """Every step of ``steps`` and of the bodies in them (loops, branches, reactions), in
    file order, a block before its reactions; not into called scripts."""
    for step in steps:
        yield step
        if isinstance(step, TBlock):
            for on in step.reactions:
                yield from iter_steps(on.body)
        elif isinstance(step, TRepeat):
            yield from iter_steps(step.body)
        elif isinstance(step, TIf):
            yield from iter_steps(step.then)
            yield from iter_steps(step.orelse)
