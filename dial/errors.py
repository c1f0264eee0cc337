"""Error types shared by every layer, and the caret rendering of script problems."""

from __future__ import annotations

from dataclasses import dataclass
from itertools import groupby
from typing import NamedTuple


class DialError(Exception):
    """Root of every error the package raises on purpose."""


class OptionError(DialError):
    """An option (of ``dial run``, or of :func:`dial.run`) out of its range or unusable:
    a usage error, exit status 2. The message names the option and what was expected."""


class Span(NamedTuple):
    """A place in a source file: 1-based line and column, ``end_col`` exclusive.

    A named tuple rather than a dataclass: a large script has one per mark, and a tuple is
    cheap to make. Spans order by line, then column.
    """

    line: int
    col: int
    end_col: int

    def to(self, other: Span) -> Span:
        """The span from the start of ``self`` to the end of ``other`` (same line)."""
        return Span(self.line, self.col, other.end_col)

    @staticmethod
    def at(line: int, col: int, length: int = 1) -> Span:
        return Span(line, col, col + max(length, 1))


@dataclass(frozen=True)
class Diagnostic:
    """One problem in a script, with the source line it points into."""

    path: str
    span: Span
    message: str
    source_line: str = ""

    @property
    def header(self) -> str:
        return f"{self.path}:{self.span.line}:{self.span.col}: {self.message}"

    def render(self) -> str:
        """``FILE:LINE:COL: message``, then the source line and a caret span.

        A long line is shown as a window of about :data:`WINDOW` characters around the
        caret, with ``...`` where it is cut.
        """
        if not self.source_line:
            return self.header
        num = str(self.span.line)
        text, start, width = _window(self.source_line.rstrip("\n"), self.span)
        pad = " " * len(num)
        caret = " " * start + "^" * width
        return f"{self.header}\n {num} | {text}\n {pad} | {caret}"


def shorten(text: str, limit: int = 40) -> str:
    """``text`` for quoting in a message: cut to ``limit`` characters, saying how long it was."""
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


WINDOW = 100  # characters of a source line shown around a caret
MAX_SHOWN = 50  # diagnostics rendered per file; the rest are counted
MAX_PROBLEMS = 100  # problems found per file: there the check of the file stops


@dataclass(frozen=True)
class Cutoff(Diagnostic):
    """Where the check of a file stopped, at its :data:`MAX_PROBLEMS`-th problem, as a
    compiler stops after so many errors: how many lines it did not check."""

    @staticmethod
    def at(path: str, line: int, text: str) -> Cutoff:
        """The check of ``path`` (whose text is ``text``) stopped at a problem on ``line``."""
        lines = text.count("\n") + (not text.endswith("\n"))  # as the parser counts them
        after = max(lines - line, 0)
        message = (
            f"too many problems: the check stopped at line {line} after {MAX_PROBLEMS}; "
            f"{after} line{'s' if after != 1 else ''} after it {'were' if after != 1 else 'was'} "
            "not checked"
        )
        return Cutoff(path, Span(line, 1, 1), message)


class TooManyProblems(Exception):
    """Raised inside the checker at a file's :data:`MAX_PROBLEMS`-th problem; the file's
    check ends there (never seen outside :mod:`dial.parser`)."""


def tally(found: int, diags: list[Diagnostic], path: str, line: int, text: str) -> int:
    """``found``, the problems of the file at ``path`` so far, the latest on ``line``. At
    :data:`MAX_PROBLEMS` the check of the file stops: its :class:`Cutoff` joins ``diags``,
    and :class:`TooManyProblems` is raised (as it is beyond, where the check stopped)."""
    if found >= MAX_PROBLEMS:
        if found == MAX_PROBLEMS:
            diags.append(Cutoff.at(path, line, text))
        raise TooManyProblems
    return found


def _window(line: str, span: Span) -> tuple[str, int, int]:
    """The part of ``line`` to show, and where the caret starts in it and how wide it is."""
    first = max(span.col - 1, 0)
    width = max(span.end_col - span.col, 1)
    if len(line) <= WINDOW:
        return line.expandtabs(1), first, width
    width = min(width, WINDOW // 2)
    lo = max(0, min(first - WINDOW // 4, len(line) - WINDOW))
    hi = min(len(line), lo + WINDOW)
    text = line[lo:hi].expandtabs(1)
    start = first - lo
    if lo > 0:
        text, start = "..." + text, start + 3
    if hi < len(line):
        text += "..."
    return text, start, width


class ScriptError(DialError):
    """A script (or a script it calls) has one or more problems.

    ``diagnostics`` is sorted by file, line and column: at most :data:`MAX_PROBLEMS` per
    file. ``cutoffs`` says where the check of a file stopped at that many, if it did.
    """

    def __init__(self, diagnostics: list[Diagnostic] | tuple[Diagnostic, ...]) -> None:
        found = sorted(diagnostics, key=lambda d: (d.path, d.span))
        self.diagnostics = tuple(d for d in found if not isinstance(d, Cutoff))
        self.cutoffs = {d.path: d for d in found if isinstance(d, Cutoff)}
        super().__init__(self.render())

    def __reduce__(self) -> tuple[type[ScriptError], tuple[tuple[Diagnostic, ...]]]:
        # Pickled (a worker process's error) as what it was made from, not its message.
        return type(self), ((*self.diagnostics, *self.cutoffs.values()),)

    def render(self) -> str:
        """Every diagnostic, at most :data:`MAX_SHOWN` per file, then how many more, and
        where the check of the file stopped if it did."""
        out: list[str] = []
        for path, group in groupby(self.diagnostics, key=lambda d: d.path):
            diags = list(group)
            out += [d.render() for d in diags[:MAX_SHOWN]]
            more = len(diags) - MAX_SHOWN
            if more > 0:
                out.append(f"{path}: {more} more problem{'s' if more != 1 else ''} not shown")
            if path in self.cutoffs:
                out.append(self.cutoffs[path].header)
        return "\n".join(out)
