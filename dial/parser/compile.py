"""Compile a checked program's execution part into the timeline, and find effector conflicts.

The compiler walks the statements once. What it needs to know about names (the bound
event of an execution line, whether a condition is valid, the script a ``@call`` names) it
asks the checker through :class:`Checks`, which also collects the problems.
"""

from __future__ import annotations

from operator import attrgetter
from typing import Protocol

from dial.errors import Span
from dial.instructions.types import FINGERS, Contact
from dial.parser.ast import (
    Abort,
    Block,
    Call,
    Condition,
    ExecLine,
    If,
    Repeat,
    Resume,
    Retry,
    Statement,
)
from dial.parser.script import (
    EventDef,
    Run,
    Script,
    Step,
    TAbort,
    TBlock,
    TCall,
    TIf,
    TOn,
    TRepeat,
    TResume,
    TRetry,
    Watch,
)

_START_LINE = attrgetter("start", "line")


class Checks(Protocol):
    """The checker's side of compilation."""

    def error(self, span: Span, message: str) -> None:
        """Report a problem."""

    def event(self, line: ExecLine) -> EventDef | None:
        """The bound event of an execution line, or None (its problem is reported)."""

    def watched(self, line: ExecLine) -> Contact | None:
        """The contact condition of the watched line's event, or None if it cannot be
        watched (then it is reported)."""

    def condition(self, cond: Condition | None) -> None:
        """Check a condition of ``@if`` or ``@repeat``."""

    def call(self, stmt: Call) -> Script | None:
        """The checked callee of a ``@call``, or None (its problems are reported)."""


def diagram_events(body: tuple[Statement, ...]) -> set[str]:
    """The events that appear on an execution line of ``body``."""
    names: set[str] = set()
    for stmt in body:
        if isinstance(stmt, Block):
            names.update(line.event for line in stmt.lines)
            for r in stmt.reactions:
                names |= diagram_events(r.body)
        elif isinstance(stmt, Repeat):
            names |= diagram_events(stmt.body)
        elif isinstance(stmt, If):
            names |= diagram_events(stmt.then) | diagram_events(stmt.orelse)
    return names


def compile_body(body: tuple[Statement, ...], checks: Checks) -> tuple[Step, ...]:
    """The timeline of ``body``."""
    steps: list[Step] = []
    for stmt in body:
        if isinstance(stmt, Block):
            steps.append(compile_block(stmt, checks))
        elif isinstance(stmt, Repeat):
            checks.condition(stmt.condition)
            inner = compile_body(stmt.body, checks)
            steps.append(TRepeat(stmt.kind, stmt.count, stmt.condition, inner, stmt.line))
        elif isinstance(stmt, If):
            checks.condition(stmt.condition)
            then, orelse = compile_body(stmt.then, checks), compile_body(stmt.orelse, checks)
            steps.append(TIf(stmt.condition, then, orelse, stmt.line))
        elif isinstance(stmt, Call):
            callee = checks.call(stmt)
            if callee is not None:
                steps.append(TCall(stmt.target, callee, stmt.line))
        elif isinstance(stmt, Resume):
            steps.append(TResume(stmt.line))
        elif isinstance(stmt, Retry):
            steps.append(TRetry(stmt.max, stmt.line))
        elif isinstance(stmt, Abort):
            steps.append(TAbort(stmt.message, stmt.line))
    return tuple(steps)


def compile_block(block: Block, checks: Checks) -> TBlock:
    """A block: its runs in the order they start (checked for conflicts), watches, reactions."""
    runs: list[Run] = []
    watches: list[Watch] = []
    for line in block.lines:
        event = checks.event(line)
        if event is None:
            continue
        contact = checks.watched(line) if line.watches else None
        if contact is not None:
            watches += (
                Watch(line.event, line.line, w.start, w.end, contact, line.span_of(w.start, w.end))
                for w in line.watches
            )
        name, number, effectors, col = line.event, line.line, event.effectors, line.column
        runs += [
            Run(name, number, s, e, h, effectors, Span(number, s + col - 1, h + col))
            for s, e, h in line.runs
        ]
    if len(runs) > 1:
        runs.sort(key=_START_LINE)
        conflicts(runs, checks)
    if len(watches) > 1:
        watches.sort(key=_START_LINE)
        overlapping_watches(watches, checks)
    reactions = tuple(
        TOn(r.condition, compile_body(r.body, checks), r.line) for r in block.reactions
    )
    return TBlock(block.line, block.length, tuple(runs), tuple(watches), reactions)


def conflicts(runs: list[Run], checks: Checks) -> None:
    """Report runs (sorted by start) that overlap their own event or share an effector.

    One sweep per effector and per event: a run conflicts when it starts before the run
    that reaches furthest so far on the same effector (or of the same event) ends, so the
    cost is linear in the number of runs.
    """
    reported: set[tuple[int, int]] = set()
    furthest: dict[str, Run] = {}  # per effector
    own: dict[str, Run] = {}  # per event
    for b in runs:
        a = own.get(b.event)
        if a is None or b.hold_end > a.hold_end:
            own[b.event] = b
        if a is not None and b.start <= a.hold_end and a.line != b.line:
            _conflict(a, b, reported, checks)
        for effector in b.effectors:
            a = furthest.get(effector)
            if a is None or b.hold_end > a.hold_end:
                furthest[effector] = b
            if a is not None and b.start <= a.hold_end:
                _conflict(a, b, reported, checks)


def _conflict(a: Run, b: Run, reported: set[tuple[int, int]], checks: Checks) -> None:
    """Report that ``b`` overlaps ``a`` (which starts no later), once per pair of lines."""
    if (a.line, b.line) in reported:
        return
    reported.add((a.line, b.line))
    ticks = _ticks(b.start, min(a.hold_end, b.hold_end))
    if a.event == b.event:
        message = f"event '{b.event}' (line {b.line}) overlaps its own run on line {a.line}"
    else:
        shared = a.effectors & b.effectors
        names = ", ".join(e for e in ("arm", *FINGERS) if e in shared)
        message = (
            f"effector conflict: '{b.event}' (line {b.line}) and '{a.event}' "
            f"(line {a.line}) both command {names}"
        )
    checks.error(b.span, f"{message} in {ticks}")


def _ticks(first: int, last: int) -> str:
    return f"tick {first}" if first == last else f"ticks {first}-{last}"


def overlapping_watches(watches: list[Watch], checks: Checks) -> None:
    """Report a watched span (sorted by start) that overlaps another of its event."""
    last: dict[str, Watch] = {}  # per event, the watch that reaches furthest so far
    for w in watches:
        prev = last.get(w.event)
        if prev is not None and w.start <= prev.end:
            ticks = _ticks(w.start, min(w.end, prev.end))
            checks.error(
                w.span,
                f"event '{w.event}' is watched twice in {ticks} (lines {prev.line} and {w.line})",
            )
        if prev is None or w.end > prev.end:
            last[w.event] = w
