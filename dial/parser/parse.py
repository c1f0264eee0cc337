"""Parse script text into a :class:`~dial.parser.ast.Program`.

The parser recovers line by line, so one pass reports every syntax problem.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from difflib import get_close_matches
from typing import Literal

from dial.errors import Diagnostic, ScriptError, Span
from dial.parser.ast import (
    Block,
    Call,
    Condition,
    Definition,
    ExecLine,
    If,
    Param,
    Program,
    Repeat,
    RunMark,
    Setting,
    Statement,
    Word,
)
from dial.parser.source import Kind, Line, scan
from dial.parser.words import WordError, tokenize
from dial.units import UnitError, parse_quantity

NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_COND = re.compile(r"(!?)([A-Za-z_][A-Za-z0-9_]*)$")
DIRECTIVES = ("scene", "tick", "repeat", "if", "else", "end", "call")
DEFAULT_MAX = 100
MAX_COUNT = 1_000_000
MAX_TICK_S = 60.0


_RepeatSpec = tuple[Literal["count", "until", "while"], int, Condition | None]


@dataclass
class _Frame:
    kind: Literal["top", "repeat", "if"]
    span: Span
    statements: list[Statement] = field(default_factory=list)
    then: list[Statement] = field(default_factory=list)
    in_else: bool = False
    repeat: _RepeatSpec | None = None
    condition: Condition | None = None
    line: int = 0


@dataclass
class _PendingLine:
    line: Line
    event: str
    event_span: Span
    first_col: int  # 0-based column of the first diagram character
    last_col: int
    runs: list[tuple[int, int, int]]  # 0-based (start, exec_end, hold_end) columns


class _Parser:
    def __init__(self, text: str, path: str) -> None:
        self.path = path
        self.lines, problems = scan(text)
        self.by_number = {ln.number: ln for ln in self.lines}
        self.diags: list[Diagnostic] = []
        for span, message in problems:
            self.error(span, message)
        self.stack: list[_Frame] = [_Frame("top", Span(1, 1, 2))]
        self.block: list[_PendingLine] = []
        self.block_ok = True
        self.definitions: dict[str, Definition] = {}
        self.scene: Setting | None = None
        self.tick: Setting | None = None
        self.tick_value: float | None = None

    def error(self, span: Span, message: str) -> None:
        ln = self.by_number.get(span.line)
        self.diags.append(Diagnostic(self.path, span, message, ln.text if ln else ""))

    # -- driver ---------------------------------------------------------------------------
    def run(self) -> Program:
        for ln in self.lines:
            if ln.kind is Kind.COMMENT:
                continue
            if ln.kind is not Kind.EXECUTION:
                self.flush()
            if ln.kind is Kind.EXECUTION:
                self.execution(ln)
            elif ln.kind is Kind.DEFINITION:
                self.definition(ln)
            elif ln.kind is Kind.DIRECTIVE:
                self.directive(ln)
            elif ln.kind is Kind.OTHER:
                self.other(ln)
        self.flush()
        while len(self.stack) > 1:
            frame = self.stack.pop()
            self.error(frame.span, f"'@{frame.kind}' is never closed: add '@end'")
        return Program(
            self.path,
            self.scene,
            self.tick_value,
            self.tick,
            tuple(self.definitions.values()),
            tuple(self.stack[0].statements),
        )

    def statements(self) -> list[Statement]:
        frame = self.stack[-1]
        return frame.statements if frame.kind != "if" or frame.in_else else frame.then

    def other(self, ln: Line) -> None:
        col = len(ln.code) - len(ln.code.lstrip())
        if col > 0:
            self.error(
                Span.at(ln.number, col + 1, len(ln.code.strip().split()[0])),
                "unexpected indentation: definitions, directives and execution lines "
                "start in column 1",
            )
        else:
            self.error(
                Span.at(ln.number, 1),
                f"unexpected '{ln.code[0]}': expected a definition ('%'), a directive ('@'), "
                "an execution line (an event name) or a comment",
            )

    # -- definitions ----------------------------------------------------------------------
    def definition(self, ln: Line) -> None:
        code = ln.code.rstrip()
        i = 1
        while i < len(code) and code[i].isspace():
            i += 1
        m = NAME.match(code, i)
        if m is None:
            what = code[i:].split()[0] if i < len(code) else ""
            self.error(
                Span.at(ln.number, i + 1, len(what)),
                f"expected an event name after '%', got '{what}'"
                if what
                else "expected an event name after '%'",
            )
            return
        event, event_span = m.group(), Span(ln.number, m.start() + 1, m.end() + 1)
        j = m.end()
        if j < len(code) and not code[j].isspace():
            self.error(
                Span.at(ln.number, j + 1),
                f"unexpected '{code[j]}' in event name '{code[m.start() : j + 1]}': "
                "names match [A-Za-z_][A-Za-z0-9_]*",
            )
            return
        while j < len(code) and code[j].isspace():
            j += 1
        im = NAME.match(code, j)
        if im is None or (im.end() < len(code) and not code[im.end()].isspace()):
            if j >= len(code):
                self.error(event_span, f"expected an instruction after event name '{event}'")
            else:
                word = code[j:].split()[0]
                self.error(
                    Span.at(ln.number, j + 1, len(word)),
                    f"expected an instruction name after '{event}', got '{word}'",
                )
            return
        instr_span = Span(ln.number, im.start() + 1, im.end() + 1)
        broken = False
        try:
            params = tokenize(ln.number, code, im.end())
        except WordError as e:
            if not e.known:
                self.error(e.span, e.message)
            params, broken = [], True
        if event in self.definitions:
            first = self.definitions[event].line
            self.error(event_span, f"event '{event}' is already defined on line {first}")
            return
        self.definitions[event] = Definition(
            event, im.group(), tuple(params), ln.number, event_span, instr_span, broken
        )

    # -- execution lines and blocks --------------------------------------------------------
    def execution(self, ln: Line) -> None:
        code = ln.code.rstrip()
        m = NAME.match(code)
        assert m is not None  # the scanner classified the line by its first character
        event, span = m.group(), Span(ln.number, 1, m.end() + 1)
        j = m.end()
        if j >= len(code):
            self.block_ok = False
            self.error(span, f"execution line for '{event}' has no diagram: add ticks after it")
            return
        if not code[j].isspace():
            self.block_ok = False
            self.error(
                Span.at(ln.number, j + 1),
                f"unexpected '{code[j]}' after event name '{event}': names match "
                "[A-Za-z_][A-Za-z0-9_]* and are followed by spaces and the diagram",
            )
            return
        while j < len(code) and code[j].isspace():
            if code[j] == "\t":
                self.block_ok = False
                self.error(
                    Span.at(ln.number, j + 1),
                    "tab before the diagram: its column is ambiguous; use spaces",
                )
                return
            j += 1
        runs: list[tuple[int, int, int]] = []
        current: list[int] | None = None  # [start, exec_end, hold_end]
        ok = True
        for c in range(j, len(code)):
            ch = code[c]
            if ch == "#":
                current = [c, c, c]
                runs.append((c, c, c))
                continue
            if ch in "=-" and current is not None:
                if ch == "=" and current[2] != current[1]:
                    ok = False
                    self.error(
                        Span.at(ln.number, c + 1),
                        "'=' after '-': within a run every '=' comes before any '-'",
                    )
                    break
                if ch == "=":
                    current[1] = c
                current[2] = c
                runs[-1] = (current[0], current[1], current[2])
                continue
            current = None
            if ch in " .":
                continue
            # Report the first problem on the line only: the rest usually follow from it.
            ok = False
            if ch in "=-":
                role = "continues" if ch == "=" else "holds"
                self.error(
                    Span.at(ln.number, c + 1),
                    f"misplaced '{ch}': it {role} a run, so it must follow that run's '#'",
                )
            elif ch == "\t":
                self.error(
                    Span.at(ln.number, c + 1),
                    "tab inside the diagram: its column is ambiguous; use spaces",
                )
            else:
                self.error(
                    Span.at(ln.number, c + 1),
                    f"unexpected '{ch}' in the diagram of '{event}'; "
                    "expected '#', '=', '-', '.' or a space",
                )
            break
        if not ok:
            self.block_ok = False
            return
        self.block.append(_PendingLine(ln, event, span, j, len(code) - 1, runs))

    def flush(self) -> None:
        pending, ok = self.block, self.block_ok
        self.block, self.block_ok = [], True
        if not pending or not ok:
            return
        base = min(p.first_col for p in pending)
        lines = tuple(
            ExecLine(
                p.event,
                tuple(
                    RunMark(
                        s - base + 1,
                        e - base + 1,
                        h - base + 1,
                        Span(p.line.number, s + 1, h + 2),
                    )
                    for s, e, h in p.runs
                ),
                p.last_col - base + 1,
                p.line.number,
                p.event_span,
            )
            for p in pending
        )
        length = max(x.last_tick for x in lines)
        self.statements().append(Block(lines, length, pending[0].line.number))

    # -- directives -----------------------------------------------------------------------
    def directive(self, ln: Line) -> None:
        code = ln.code.rstrip()
        m = NAME.match(code, 1)
        name = m.group() if m else ""
        end = m.end() if m else 1
        span = Span(ln.number, 1, end + 1)
        if name not in DIRECTIVES or (end < len(code) and not code[end].isspace()):
            close = get_close_matches(name, DIRECTIVES, n=2)
            hint = f"; did you mean {' or '.join('@' + c for c in close)}?" if close else ""
            valid = ", ".join("@" + d for d in DIRECTIVES)
            self.error(
                Span(ln.number, 1, max(end, 2) + 1),
                f"unknown directive '{code.split()[0]}'{hint} (valid: {valid})",
            )
            return
        words: list[Word] | None = None
        try:
            params = tokenize(ln.number, code, end)
            keyed = next((p for p in params if p.key is not None), None)
            if keyed is not None:
                self.error(keyed.span, f"unexpected '{keyed.key}=' in '@{name}'")
            else:
                words = [w for p in params for w in p.words]
        except WordError as e:
            if not e.known:
                self.error(e.span, e.message)
        # Block structure is kept even when the arguments are bad, so that one
        # mistake does not also unbalance every '@end' after it.
        if name == "repeat":
            spec = self.repeat_spec(ln, span, words) if words is not None else None
            self.stack.append(_Frame("repeat", span, repeat=spec, line=ln.number))
        elif name == "if":
            cond = self.if_condition(span, words) if words is not None else None
            self.stack.append(_Frame("if", span, condition=cond, line=ln.number))
        elif name == "else":
            self.d_else(span)
        elif name == "end":
            self.d_end(span)
        if words is None:
            return
        if name in ("else", "end"):
            self._arity(span, name, words, 0, "no arguments")
        elif name == "scene":
            self.d_scene(ln, span, words)
        elif name == "tick":
            self.d_tick(ln, span, words)
        elif name == "call" and self._arity(span, "call", words, 1, "one path: @call FILE.dial"):
            self.statements().append(Call(words[0].text, ln.number, words[0].span))

    def _arity(self, span: Span, name: str, words: list[Word], n: int, form: str) -> bool:
        if len(words) == n:
            return True
        where = words[n].span.to(words[-1].span) if len(words) > n else span
        self.error(where, f"'@{name}' takes {form}")
        return False

    def _top_level(self, span: Span, name: str) -> bool:
        if len(self.stack) > 1:
            self.error(span, f"'@{name}' must be at the top level, outside '@repeat' and '@if'")
            return False
        return True

    def d_scene(self, ln: Line, span: Span, words: list[Word]) -> None:
        if not self._arity(span, "scene", words, 1, "one scene name or path: @scene NAME_OR_PATH"):
            return
        if not self._top_level(span, "scene"):
            return
        if self.scene is not None:
            self.error(span, f"'@scene' is already set on line {self.scene.line}")
            return
        self.scene = Setting(words[0].text, ln.number, words[0].span)

    def d_tick(self, ln: Line, span: Span, words: list[Word]) -> None:
        if not self._arity(span, "tick", words, 1, "one duration: @tick SECONDS (e.g. @tick 0.25)"):
            return
        if not self._top_level(span, "tick"):
            return
        if self.tick is not None:
            self.error(span, f"'@tick' is already set on line {self.tick.line}")
            return
        w = words[0]
        try:
            value = parse_quantity(w.text, "time", "s")
        except UnitError as e:
            self.error(w.span, f"bad tick length: {e}")
            return
        if not 0 < value <= MAX_TICK_S:
            self.error(
                w.span, f"tick length must be above 0 s and at most {MAX_TICK_S:g} s, got {w.text}"
            )
            return
        self.tick, self.tick_value = Setting(w.text, ln.number, w.span), value

    def condition(self, word: Word) -> Condition | None:
        m = _COND.match(word.text)
        if m is None:
            self.error(word.span, f"expected a condition EVENT or !EVENT, got '{word.text}'")
            return None
        return Condition(m.group(2), m.group(1) == "!", word.span)

    def _count(self, word: Word, what: str) -> int | None:
        if not word.text.isdigit() or not 1 <= int(word.text) <= MAX_COUNT:
            self.error(word.span, f"expected {what}, got '{word.text}'")
            return None
        return int(word.text)

    def repeat_spec(self, ln: Line, span: Span, words: list[Word]) -> _RepeatSpec | None:
        form = "N, or until/while COND [max N]"
        if not words:
            self.error(span, f"'@repeat' takes {form}")
            return None
        head = words[0].text
        if head not in ("until", "while"):
            if not self._arity(span, "repeat", words, 1, form):
                return None
            n = self._count(words[0], f"a repeat count from 1 to {MAX_COUNT}, until or while")
            return None if n is None else ("count", n, None)
        if len(words) not in (2, 4) or (len(words) == 4 and words[2].text != "max"):
            self.error(Span(ln.number, 1, len(ln.code.rstrip()) + 1), f"'@repeat' takes {form}")
            return None
        cond = self.condition(words[1])
        limit = (
            self._count(words[3], f"a loop limit from 1 to {MAX_COUNT}")
            if len(words) == 4
            else DEFAULT_MAX
        )
        if cond is None or limit is None:
            return None
        return ("until" if head == "until" else "while", limit, cond)

    def if_condition(self, span: Span, words: list[Word]) -> Condition | None:
        if not self._arity(span, "if", words, 1, "one condition: @if EVENT or @if !EVENT"):
            return None
        return self.condition(words[0])

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
            self.error(span, "'@end' without a matching '@repeat' or '@if'")
            return
        frame = self.stack.pop()
        stmt: Statement
        if frame.kind == "repeat":
            if not frame.statements and frame.repeat is not None:
                self.error(frame.span, "'@repeat' encloses no execution lines")
                return
            if frame.repeat is None:
                return  # its header was reported as an error
            kind, count, cond = frame.repeat
            body = tuple(frame.statements)
            stmt = Repeat(kind, count, cond, body, frame.line, frame.span)
        else:
            if frame.condition is None:
                return
            stmt = If(frame.condition, tuple(frame.then), tuple(frame.statements), frame.line)
        self.statements().append(stmt)


def parse_partial(text: str, path: str = "<script>") -> tuple[Program, list[Diagnostic]]:
    """Parse what can be parsed; return the program and every syntax problem."""
    parser = _Parser(text, path)
    program = parser.run()
    return program, parser.diags


def parse(text: str, path: str = "<script>") -> Program:
    """Parse ``text``; raise :class:`~dial.errors.ScriptError` listing every syntax problem."""
    program, diags = parse_partial(text, path)
    if diags:
        raise ScriptError(diags)
    return program


__all__ = ["DIRECTIVES", "Param", "parse", "parse_partial"]
