"""The typed, immutable program a script parses to.

Spans are excluded from equality, so a program compares equal to the same
program written with different spacing (``parse(fmt(x)) == parse(x)``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, NamedTuple

from dial.errors import Span

_NOSPAN = Span(0, 0, 0)


@dataclass(frozen=True, slots=True)
class Word:
    """One whitespace-separated word of a parameter."""

    text: str
    span: Span = field(default=_NOSPAN, compare=False)


@dataclass(frozen=True, slots=True)
class Param:
    """A parameter as written: a bare word, a quoted group, or ``key=value``.

    A quoted group contributes each of its words in turn, as in the paper's
    ``"0x0666_0x0222 400"``.
    """

    key: str | None
    words: tuple[Word, ...]
    quoted: bool
    span: Span = field(default=_NOSPAN, compare=False)

    def render(self) -> str:
        body = " ".join(w.text for w in self.words)
        if self.quoted:
            body = f'"{body}"'
        return f"{self.key}={body}" if self.key is not None else body


@dataclass(frozen=True, slots=True)
class Definition:
    """``% EVENT INSTRUCTION [PARAMS]``."""

    event: str
    instruction: str
    params: tuple[Param, ...]
    line: int = field(default=0, compare=False)
    event_span: Span = field(default=_NOSPAN, compare=False)
    instruction_span: Span = field(default=_NOSPAN, compare=False)
    broken: bool = field(default=False, compare=False)  # its parameters did not tokenize


class RunMark(NamedTuple):
    """One run drawn on an execution line, in block ticks (1-based, inclusive).

    ``exec_end`` is the last ``#``/``=`` tick and ``hold_end`` the last tick
    including ``-`` (equal to ``exec_end`` when there is no hold). Its place in the
    text is :meth:`ExecLine.span_of`.
    """

    start: int
    exec_end: int
    hold_end: int


class WatchMark(NamedTuple):
    """A watched span ``~~~`` on an execution line, in block ticks (1-based, inclusive)."""

    start: int
    end: int


@dataclass(frozen=True, slots=True)
class ExecLine:
    """An execution line: an event name and its diagram (runs, or watched spans)."""

    event: str
    runs: tuple[RunMark, ...]
    last_tick: int  # rightmost non-space diagram tick, counting '.' and '~'
    line: int = field(default=0, compare=False)
    watches: tuple[WatchMark, ...] = ()
    column: int = field(default=1, compare=False)  # the text column of the block's tick 1

    def span_of(self, first: int, last: int) -> Span:
        """Where block ticks ``first..last`` are drawn on this line."""
        return Span(self.line, first + self.column - 1, last + self.column)

    @property
    def event_span(self) -> Span:
        """The event name, in column 1."""
        return Span(self.line, 1, len(self.event) + 1)


@dataclass(frozen=True, slots=True)
class Condition:
    """``EVENT`` or ``!EVENT``: whether the latest run of EVENT ended ``done``."""

    event: str
    negated: bool
    span: Span = field(default=_NOSPAN, compare=False)

    def __str__(self) -> str:
        return ("!" if self.negated else "") + self.event


@dataclass(frozen=True, slots=True)
class Block:
    """Consecutive execution lines sharing one tick axis, and the reactions to its monitors."""

    lines: tuple[ExecLine, ...]
    length: int
    line: int = field(default=0, compare=False)
    reactions: tuple[On, ...] = ()

    @property
    def watched(self) -> tuple[str, ...]:
        """The events watched in this block, in line order, each once."""
        return tuple(dict.fromkeys(ln.event for ln in self.lines if ln.watches))


@dataclass(frozen=True, slots=True)
class Repeat:
    """``@repeat N`` (kind ``count``) or ``@repeat until/while COND [max N]``."""

    kind: Literal["count", "until", "while"]
    count: int
    condition: Condition | None
    body: tuple[Statement, ...]
    line: int = field(default=0, compare=False)
    span: Span = field(default=_NOSPAN, compare=False)


@dataclass(frozen=True, slots=True)
class If:
    """``@if COND`` ... [``@else`` ...] ``@end``."""

    condition: Condition
    then: tuple[Statement, ...]
    orelse: tuple[Statement, ...]
    line: int = field(default=0, compare=False)


@dataclass(frozen=True, slots=True)
class Call:
    """``@call FILE.dial``; ``target`` is the path as written."""

    target: str
    line: int = field(default=0, compare=False)
    span: Span = field(default=_NOSPAN, compare=False)
    depth: int = field(default=0, compare=False)  # its nesting level, counting callers' calls


@dataclass(frozen=True, slots=True)
class On:
    """``@on COND`` ... ``@end`` after a block: the reaction when a monitor fires."""

    condition: Condition
    body: tuple[Statement, ...]
    line: int = field(default=0, compare=False)


@dataclass(frozen=True, slots=True)
class Resume:
    """``@resume``: go on after the interrupted block."""

    line: int = field(default=0, compare=False)


@dataclass(frozen=True, slots=True)
class Retry:
    """``@retry [max N]``: run the interrupted block again, at most ``max`` times."""

    max: int
    line: int = field(default=0, compare=False)


@dataclass(frozen=True, slots=True)
class Abort:
    """``@abort "MESSAGE"``: end the run with an error naming the monitor."""

    message: str
    line: int = field(default=0, compare=False)


Ending = Resume | Retry | Abort
Statement = Block | Repeat | If | Call | Resume | Retry | Abort


@dataclass(frozen=True, slots=True)
class Setting:
    """A top-level ``@scene`` or ``@tick`` value as written."""

    text: str
    line: int = field(default=0, compare=False)
    span: Span = field(default=_NOSPAN, compare=False)


@dataclass(frozen=True, slots=True)
class Program:
    """A parsed script: its settings, definitions and execution part."""

    path: str = field(compare=False)
    scene: Setting | None
    tick: float | None
    tick_setting: Setting | None
    definitions: tuple[Definition, ...]
    body: tuple[Statement, ...]
