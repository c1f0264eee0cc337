"""Error types shared by every layer, and the caret rendering of script problems."""

from __future__ import annotations

from dataclasses import dataclass


class DialError(Exception):
    """Root of every error the package raises on purpose."""


class OptionError(DialError):
    """An option (of ``dial run``, or of :func:`dial.run`) out of its range or unusable:
    a usage error, exit status 2. The message names the option and what was expected."""


@dataclass(frozen=True, order=True)
class Span:
    """A place in a source file: 1-based line and column, ``end_col`` exclusive."""

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
        """``FILE:LINE:COL: message``, then the source line and a caret span."""
        if not self.source_line:
            return self.header
        num = str(self.span.line)
        text = self.source_line.rstrip("\n").expandtabs(1)
        width = max(self.span.end_col - self.span.col, 1)
        pad = " " * len(num)
        caret = " " * (self.span.col - 1) + "^" * width
        return f"{self.header}\n {num} | {text}\n {pad} | {caret}"


class ScriptError(DialError):
    """A script (or a script it calls) has one or more problems.

    ``diagnostics`` is sorted by file, line and column.
    """

    def __init__(self, diagnostics: list[Diagnostic] | tuple[Diagnostic, ...]) -> None:
        self.diagnostics = tuple(sorted(diagnostics, key=lambda d: (d.path, d.span)))
        super().__init__(self.render())

    def render(self) -> str:
        return "\n".join(d.render() for d in self.diagnostics)
