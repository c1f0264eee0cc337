"""The nesting of a script's statements: ``@repeat``, ``@if``, ``@on`` and reaction endings.

:class:`Structure` keeps the stack of open directives, so that blocks and calls land in the
right statement list, and reports misplaced directives: an ``@end`` without an opening, an
``@on`` after no block, an ending outside ``@on``, a statement after an ending.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Literal

from dial.errors import Span
from dial.parser import directives as args
from dial.parser.ast import (
    Abort,
    Block,
    Condition,
    Ending,
    If,
    On,
    Param,
    Repeat,
    Resume,
    Retry,
    Statement,
    Word,
)

ENDINGS = {Resume: "resume", Retry: "retry", Abort: "abort"}
# Levels of '@repeat', '@if', '@on' and '@call' (through every called script): the checker,
# the display and the runner recurse once per level, so a limit keeps them off Python's
# recursion limit, with room to spare.
MAX_NESTING = 100
FrameKind = Literal["top", "repeat", "if", "on"]


@dataclass
class _Frame:
    kind: FrameKind
    span: Span
    statements: list[Statement] = field(default_factory=list)
    then: list[Statement] = field(default_factory=list)
    in_else: bool = False
    repeat: args.RepeatSpec | None = None
    condition: Condition | None = None  # of '@if'; of '@on' only when it attaches to a block
    line: int = 0
    too_deep: bool = False  # beyond MAX_NESTING: reported, and dropped with what it holds
    # Per statement list (False: ``statements``, True: ``then``), how long it was when a
    # block with errors was left out of it: an '@on' right after that block is not also
    # reported as following no block.
    dropped: dict[bool, int] = field(default_factory=dict)

    @property
    def in_then(self) -> bool:
        return self.kind == "if" and not self.in_else

    lost: bool = False  # a nested directive of it was dropped (its problem is reported)


class Structure:
    """The open directives, innermost last, and the statements each has collected."""

    def __init__(self, error: args.OnError, depth: int = 0) -> None:
        self.error = error
        self.base = depth  # the nesting level of the '@call' that runs this script
        self.stack: list[_Frame] = [_Frame("top", Span(1, 1, 2))]
        self.lenient: set[int] = set()  # blocks whose '@on' headers were broken
        self.watching = False  # some block watches an event: its '@on' must be checked

    @property
    def nested(self) -> bool:
        return len(self.stack) > 1

    def statements(self) -> list[Statement]:
        frame = self.stack[-1]
        return frame.then if frame.in_then else frame.statements

    def add(self, stmt: Statement, span: Span) -> None:
        """Append ``stmt`` (which starts at ``span``) to the current list, if reachable."""
        if self.reachable(span):
            self.statements().append(stmt)

    def drop_block(self) -> None:
        """A block with errors is left out; remember where, for a following ``@on``."""
        frame = self.stack[-1]
        frame.dropped[frame.in_then] = len(self.statements())

    def reachable(self, span: Span) -> bool:
        """False, reported, if a reaction ending precedes ``span`` in its statement list."""
        stmts = self.statements()
        last = stmts[-1] if stmts else None
        if isinstance(last, Resume | Retry | Abort):
            self.error(
                span,
                f"unreachable: '@{ENDINGS[type(last)]}' on line {last.line} ends the reaction "
                "before this line",
            )
            return False
        return True

    def finish(self) -> tuple[Statement, ...]:
        """Close what is left open (reported) and return the top-level statements."""
        while len(self.stack) > 1:
            frame = self.stack.pop()
            self.error(frame.span, f"'@{frame.kind}' is never closed: add '@end'")
        body = tuple(self.stack[0].statements)
        if self.watching:
            self.unhandled_watches(body)
        return body

    def unhandled_watches(self, body: tuple[Statement, ...]) -> None:
        """Report every watched span whose event has no ``@on`` after its block."""
        for stmt in body:
            if isinstance(stmt, Block):
                handled = {r.condition.event for r in stmt.reactions}
                for ln in stmt.lines if stmt.line not in self.lenient else ():
                    for w in ln.watches if ln.event not in handled else ():
                        self.error(
                            ln.span_of(*w),
                            f"event '{ln.event}' is watched here, but no '@on {ln.event}' or "
                            f"'@on !{ln.event}' follows the block: add one, or remove the '~'",
                        )
                for r in stmt.reactions:
                    self.unhandled_watches(r.body)
            elif isinstance(stmt, Repeat):
                self.unhandled_watches(stmt.body)
            elif isinstance(stmt, If):
                self.unhandled_watches(stmt.then)
                self.unhandled_watches(stmt.orelse)

    # -- directives -----------------------------------------------------------------------
    def open(
        self, name: str, span: Span, line_span: Span, words: list[Word] | None, number: int
    ) -> None:
        """``@repeat``, ``@if`` or ``@on``: push a frame that ``@end`` closes."""
        self.reachable(span)
        report = self.error
        deep = self.stack[-1].too_deep or not self.within_limit(name, span)
        if name == "repeat":
            spec = args.repeat_spec(report, span, line_span, words) if words is not None else None
            frame = _Frame("repeat", span, repeat=spec, line=number)
        elif name == "if":
            cond = args.one_condition(report, span, "if", words) if words is not None else None
            frame = _Frame("if", span, condition=cond, line=number)
        else:
            cond = args.one_condition(report, span, "on", words) if words is not None else None
            cond = self.watched_block(span, None if deep else cond)
            frame = _Frame("on", span, condition=cond, line=number)
        frame.too_deep = deep
        self.stack.append(frame)

    @property
    def level(self) -> int:
        """The nesting level of a directive opened now, counting the calls that lead here."""
        return self.base + len(self.stack)

    def within_limit(self, name: str, span: Span) -> bool:
        """Whether ``@name`` opened now stays within :data:`MAX_NESTING` (if not, reported)."""
        if self.level <= MAX_NESTING:
            return True
        if not self.stack[-1].too_deep:  # only the first directive beyond the limit
            calls = f" (the calls that lead to this script take {self.base})" if self.base else ""
            self.error(
                span,
                f"'@{name}' is nested {self.level} levels deep: at most {MAX_NESTING} levels of "
                f"'@repeat', '@if', '@on' and '@call' are allowed{calls}",
            )
        return False

    def watched_block(self, span: Span, cond: Condition | None) -> Condition | None:
        """``cond`` if the ``@on`` directly follows a block that watches its event."""
        stmts = self.statements()
        block = stmts[-1] if stmts and isinstance(stmts[-1], Block) else None
        if block is None:
            frame = self.stack[-1]
            if frame.dropped.get(frame.in_then) != len(stmts):
                self.error(span, "'@on' must come directly after the block it watches")
            return None
        if cond is not None and cond.event not in block.watched:
            watched = block.watched
            detail = (
                f"watched there: {', '.join(watched)}"
                if watched
                else "that block watches nothing: mark ticks with '~' on a contact event's line"
            )
            self.error(
                cond.span,
                f"'@on {cond}': '{cond.event}' is not watched in the block on line "
                f"{block.line} ({detail})",
            )
            cond = None
        if cond is None:
            self.lenient.add(block.line)
        return cond

    def ending(
        self, name: str, span: Span, params: list[Param], words: list[Word], number: int
    ) -> None:
        """``@resume``, ``@retry [max N]``, ``@abort "MESSAGE"``."""
        stmt: Ending | None = None
        if name == "resume":
            if args.arity(self.error, span, name, words, 0, "no arguments"):
                stmt = Resume(number)
        elif name == "retry":
            limit = args.retry_max(self.error, span, words)
            stmt = None if limit is None else Retry(limit, number)
        else:
            message = args.abort_message(self.error, span, params)
            stmt = None if message is None else Abort(message, number)
        if not any(f.kind == "on" for f in self.stack):
            self.error(
                span,
                f"'@{name}' outside '@on': it ends a reaction, so it belongs between "
                "'@on COND' and its '@end'",
            )
        elif stmt is not None:
            self.add(stmt, span)

    def d_else(self, span: Span) -> None:
        frame = self.stack[-1]
        if frame.kind != "if":
            self.error(span, "'@else' without a matching '@if'")
        elif frame.in_else:
            self.error(span, f"second '@else' for the '@if' on line {frame.line}")
        else:
            frame.in_else = True

    def d_end(self, span: Span) -> None:
        if len(self.stack) == 1:
            self.error(span, "'@end' without a matching '@repeat', '@if' or '@on'")
            return
        frame = self.stack.pop()
        if frame.too_deep or (frame.lost and not frame.statements and not frame.then):
            self.stack[-1].lost = True
            return
        if frame.kind == "on":
            if frame.condition is not None:  # else its header was reported as an error
                stmts = self.statements()
                block = stmts[-1]
                assert isinstance(block, Block)  # nothing is added here while '@on' is open
                on = On(frame.condition, tuple(frame.statements), frame.line)
                stmts[-1] = replace(block, reactions=(*block.reactions, on))
            return
        stmt = self.closed(frame)
        if stmt is None:
            self.stack[-1].lost = True
        else:
            self.statements().append(stmt)

    def closed(self, frame: _Frame) -> Repeat | If | None:
        """The statement an ``@end`` closes, or None if it has a problem (reported)."""
        if frame.kind == "repeat":
            if frame.repeat is None:
                return None  # its header was reported as an error
            if not frame.statements:
                self.error(frame.span, "'@repeat' encloses no execution lines")
                return None
            kind, count, cond = frame.repeat
            return Repeat(kind, count, cond, tuple(frame.statements), frame.line, frame.span)
        if frame.condition is None:
            return None
        return If(frame.condition, tuple(frame.then), tuple(frame.statements), frame.line)
