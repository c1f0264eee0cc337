"""Parse script text into a :class:`~dial.parser.ast.Program`.

The parser recovers line by line, so one pass reports every syntax problem.
"""

from __future__ import annotations

import re
from difflib import get_close_matches
from functools import lru_cache
from typing import NamedTuple

from dial.errors import Diagnostic, ScriptError, Span, TooManyProblems, shorten, tally
from dial.parser import directives as args
from dial.parser.ast import (
    Block,
    Call,
    Definition,
    ExecLine,
    Param,
    Program,
    RunMark,
    Setting,
    WatchMark,
    Word,
)
from dial.parser.diagram import Diagram, read_diagram
from dial.parser.source import Kind, Line, scan
from dial.parser.structure import Structure
from dial.parser.words import WordError, bare_words, tokenize
from dial.units import UnitError, parse_quantity

NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_GAP = re.compile(r"[^\S\t]*")  # whitespace up to the diagram; a tab there is an error
DIRECTIVES = (
    *("scene", "tick", "repeat", "if", "else", "end", "call"),
    *("on", "resume", "retry", "abort"),
)
MAX_TICK_S = 60.0


class _PendingLine(NamedTuple):
    number: int
    event: str
    first_col: int  # 0-based column of the first diagram character
    last_col: int
    marks: Diagram  # 0-based columns


class _Problem(NamedTuple):
    col: int  # 1-based, on the line being read
    end_col: int
    message: str


def _read_execution(code: str) -> tuple[str, int, int, Diagram] | _Problem:
    # Long lines are rare and costly to keep: only short ones are cached.
    return _read_short(code) if len(code) <= 400 else _read_line(code)


def _read_line(code: str) -> tuple[str, int, int, Diagram] | _Problem:
    """An execution line (comments blanked, right-stripped): its event, the first and last
    diagram columns and the marks; or its first problem.

    A pure function of the text, cached: long scripts repeat their lines.
    """
    m = NAME.match(code)
    assert m is not None  # the scanner classified the line by its first character
    event = m.group()
    j = m.end()
    if j >= len(code):
        return _Problem(
            1, j + 1, f"execution line for '{event}' has no diagram: add ticks after it"
        )
    if not code[j].isspace():
        return _Problem(
            j + 1,
            j + 2,
            f"unexpected '{code[j]}' after event name '{event}': names match "
            "[A-Za-z_][A-Za-z0-9_]* and are followed by spaces and the diagram",
        )
    first = _GAP.match(code, j).end()  # type: ignore[union-attr]  # matches empty too
    if code[first] == "\t":
        return _Problem(
            first + 1, first + 2, "tab before the diagram: its column is ambiguous; use spaces"
        )
    marks = read_diagram(code, first, event)
    if not isinstance(marks, Diagram):
        return _Problem(marks[0] + 1, marks[0] + 2, marks[1])
    return event, first, len(code) - 1, marks


_read_short = lru_cache(maxsize=4096)(_read_line)


class _Parser:
    def __init__(self, text: str, path: str, depth: int = 0) -> None:
        self.path, self.text = path, text
        self.lines, self.lexical = scan(text)
        self.diags: list[Diagnostic] = []
        self.at = 0  # the line being read (after the last: the end of the file)
        self.structure = Structure(self.error, depth)
        self.block: list[_PendingLine] = []
        self.block_ok = True
        self.definitions: dict[str, Definition] = {}
        self.scene: Setting | None = None
        self.tick: Setting | None = None
        self.tick_value: float | None = None

    def error(self, span: Span, message: str) -> None:
        ln = self.lines[span.line - 1] if 0 < span.line <= len(self.lines) else None  # numbered 1..
        self.diags.append(Diagnostic(self.path, span, message, ln.text if ln else ""))
        tally(len(self.diags), self.diags, self.path, max(span.line, self.at), self.text)

    # -- driver ---------------------------------------------------------------------------
    def run(self) -> Program:
        for span, message in self.lexical:
            self.error(span, message)
        execution, comment = Kind.EXECUTION, Kind.COMMENT
        for ln in self.lines:
            self.at = ln.number
            kind = ln.kind
            if kind is execution:
                self.execution(ln)
                continue
            if kind is comment:
                continue
            if self.block or not self.block_ok:
                self.flush()
            if kind is Kind.DEFINITION:
                self.definition(ln)
            elif kind is Kind.DIRECTIVE:
                self.directive(ln)
            elif kind is Kind.OTHER:
                self.other(ln)
        self.at = len(self.lines)
        self.flush()
        body = self.structure.finish()
        # The structure reports through this parser: drop it, so that no reference cycle
        # keeps the lines alive until a garbage collection.
        del self.structure
        return Program(
            self.path,
            self.scene,
            self.tick_value,
            self.tick,
            tuple(self.definitions.values()),
            body,
        )

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
        read = _read_execution(ln.code.rstrip())
        number = ln.number
        if isinstance(read, _Problem):
            self.block_ok = False
            self.error(Span(number, read.col, read.end_col), read.message)
            return
        event, first, last, marks = read
        self.block.append(_PendingLine(number, event, first, last, marks))

    def flush(self) -> None:
        pending, ok = self.block, self.block_ok
        self.block, self.block_ok = [], True
        if not ok:
            self.structure.drop_block()
            return
        if not pending:
            return
        base = min([p.first_col for p in pending])
        self.structure.watching = self.structure.watching or any(p.marks.watches for p in pending)
        lines = tuple([self.exec_line(p, base) for p in pending])
        length = max(x.last_tick for x in lines)
        self.structure.add(Block(lines, length, pending[0].number), lines[0].event_span)

    @staticmethod
    def exec_line(p: _PendingLine, base: int) -> ExecLine:
        shift = 1 - base
        runs = tuple([RunMark(s + shift, e + shift, h + shift) for s, e, h in p.marks.runs])
        watches = tuple([WatchMark(s + shift, e + shift) for s, e in p.marks.watches])
        return ExecLine(p.event, runs, p.last_col + shift, p.number, watches, base + 1)

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
                f"unknown directive '{shorten(code.split()[0])}'{hint} (valid: {valid})",
            )
            return
        read = self.arguments(ln.number, code, end, name)
        params, words = read if read is not None else (None, None)
        # Block structure is kept even when the arguments are bad, so that one
        # mistake does not also unbalance every '@end' after it.
        if name in ("repeat", "if", "on"):
            line_span = Span(ln.number, 1, len(code) + 1)
            self.structure.open(name, span, line_span, words, ln.number)
        elif name == "else":
            self.structure.d_else(span)
        elif name == "end":
            self.structure.d_end(span)
        if words is None or params is None:
            return
        if name in ("else", "end"):
            args.arity(self.error, span, name, words, 0, "no arguments")
        elif name == "scene":
            self.d_scene(ln, span, words)
        elif name == "tick":
            self.d_tick(ln, span, words)
        elif name == "call":
            form = "one path: @call FILE.dial"
            if (
                args.arity(self.error, span, "call", words, 1, form)
                and args.file_path(self.error, words[0], "the called script's path")
                and self.structure.within_limit("call", span)
            ):
                level = self.structure.level
                self.structure.add(Call(words[0].text, ln.number, words[0].span, level), span)
        elif name in ("resume", "retry", "abort"):
            self.structure.ending(name, span, params, words, ln.number)

    def arguments(
        self, number: int, code: str, end: int, name: str
    ) -> tuple[list[Param], list[Word]] | None:
        """A directive's parameters and their words, or None if they are malformed."""
        words = bare_words(number, code, end)
        if words is not None:  # no quotes, no key=value: as most directives are
            params = [Param(None, (w,), False, w.span) for w in words] if name == "abort" else []
            return params, words
        try:
            params = tokenize(number, code, end)
        except WordError as e:
            if not e.known:
                self.error(e.span, e.message)
            return None
        keyed = next((p for p in params if p.key is not None), None)
        if keyed is not None:
            self.error(keyed.span, f"unexpected '{keyed.key}=' in '@{name}'")
            return None
        return params, [w for p in params for w in p.words]

    def _top_level(self, span: Span, name: str) -> bool:
        if self.structure.nested:
            self.error(
                span, f"'@{name}' must be at the top level, outside '@repeat', '@if' and '@on'"
            )
            return False
        return True

    def d_scene(self, ln: Line, span: Span, words: list[Word]) -> None:
        form = "one scene name or path: @scene NAME_OR_PATH"
        if not args.arity(self.error, span, "scene", words, 1, form):
            return
        if not self._top_level(span, "scene"):
            return
        if not args.file_path(self.error, words[0], "the scene name or path"):
            return
        if self.scene is not None:
            self.error(span, f"'@scene' is already set on line {self.scene.line}")
            return
        self.scene = Setting(words[0].text, ln.number, words[0].span)

    def d_tick(self, ln: Line, span: Span, words: list[Word]) -> None:
        form = "one duration: @tick SECONDS (e.g. @tick 0.25)"
        if not args.arity(self.error, span, "tick", words, 1, form):
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


def parse_partial(
    text: str, path: str = "<script>", *, depth: int = 0
) -> tuple[Program, list[Diagnostic]]:
    """Parse what can be parsed; return the program and every syntax problem.

    ``depth`` is the nesting level of the ``@call`` that runs this script, if any: it counts
    towards :data:`~dial.parser.structure.MAX_NESTING`.
    """
    parser = _Parser(text, path, depth)
    try:
        program = parser.run()
    except TooManyProblems:  # what was read so far, nothing after it (its Cutoff is last)
        program = Program(path, None, None, None, tuple(parser.definitions.values()), ())
    return program, parser.diags


def parse(text: str, path: str = "<script>") -> Program:
    """Parse ``text``; raise :class:`~dial.errors.ScriptError` listing every syntax problem."""
    program, diags = parse_partial(text, path)
    if diags:
        raise ScriptError(diags)
    return program


__all__ = ["DIRECTIVES", "Param", "parse", "parse_partial"]
