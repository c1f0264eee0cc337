"""Split a script into physical lines, with comments masked out.

Comments are replaced by spaces rather than removed, so that every remaining
character keeps its column: columns are ticks in an execution line.
"""

from __future__ import annotations

from enum import Enum
from typing import NamedTuple

from dial.errors import Span

_NAME_START = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_")


class Kind(Enum):
    BLANK = "blank"
    COMMENT = "comment"
    DEFINITION = "definition"
    DIRECTIVE = "directive"
    EXECUTION = "execution"
    OTHER = "other"


class Line(NamedTuple):
    """One physical line.

    ``code`` is the text with comments blanked out (same length as ``text``).
    ``comment_at`` is the 0-based column where a trailing comment starts, if the
    line ends in a comment that opened on this line; ``foreign`` is set when a
    comment crosses into or out of this line or sits between code, so that tools
    that rewrite lines (``dial fmt``) leave it alone.
    """

    number: int
    text: str
    code: str
    kind: Kind
    has_comment: bool
    comment_at: int | None
    foreign: bool


_BY_FIRST = {"%": Kind.DEFINITION, "@": Kind.DIRECTIVE} | dict.fromkeys(_NAME_START, Kind.EXECUTION)


def _kind(stripped: str, has_comment: bool) -> Kind:
    if not stripped:
        return Kind.COMMENT if has_comment else Kind.BLANK
    first = stripped[0]
    if first == "%":
        return Kind.DEFINITION
    if first == "@":
        return Kind.DIRECTIVE
    return Kind.EXECUTION if first in _NAME_START else Kind.OTHER


class _Masker:
    """Blanks out the comments of lines that have (or continue) one, across lines."""

    def __init__(self) -> None:
        self.open: Span | None = None  # where an unclosed /* started
        self.problems: list[tuple[Span, str]] = []

    def mask(self, number: int, raw: str) -> Line:
        started_in_comment = self.open is not None
        quotes = not started_in_comment and raw[:1] in ("%", "@")
        code = list(raw)
        comment_cols: list[int] = []
        i, n = 0, len(raw)
        in_quote: int | None = None
        while i < n:
            if self.open is not None:
                close = raw.find("*/", i)
                end = n if close < 0 else close + 2
                code[i:end] = " " * (end - i)
                self.open = None if close >= 0 else self.open
                i = end
            elif in_quote is not None:
                close = raw.find('"', i)
                i, in_quote = (n, in_quote) if close < 0 else (close + 1, None)
            elif quotes and raw[i] == '"':
                in_quote, i = i, i + 1
            elif raw.startswith("//", i):
                comment_cols.append(i)
                code[i:] = " " * (n - i)
                break
            elif raw.startswith("/*", i):
                comment_cols.append(i)
                self.open = Span.at(number, i + 1, 2)
                code[i : i + 2] = "  "
                i += 2
            else:
                i += 1
        if in_quote is not None:
            self.problems.append(
                (Span(number, in_quote + 1, n + 1), "unterminated string: add a closing '\"'")
            )
        masked = "".join(code)
        comment_at = comment_cols[0] if len(comment_cols) == 1 else None
        foreign = (
            started_in_comment
            or self.open is not None
            or len(comment_cols) > 1
            or (comment_at is not None and masked[comment_at:].strip() != "")
        )
        has_comment = started_in_comment or bool(comment_cols)
        kind = _kind(masked.rstrip(), has_comment)
        return Line(number, raw, masked, kind, has_comment, comment_at, foreign)


def scan(text: str) -> tuple[list[Line], list[tuple[Span, str]]]:
    """Return the lines of ``text`` and any lexical problems (span, message)."""
    lines: list[Line] = []
    masker = _Masker()
    physical = text.split("\n")
    if physical and physical[-1] == "":
        physical.pop()
    for number, raw in enumerate(physical, start=1):
        raw = raw.removesuffix("\r")
        if masker.open is None and "/" not in raw and ('"' not in raw or raw.count('"') % 2 == 0):
            # No comment: most lines. An even number of quotes closes every string.
            kind = _BY_FIRST.get(raw[:1]) or (Kind.OTHER if raw.strip() else Kind.BLANK)
            lines.append(Line(number, raw, raw, kind, False, None, False))
        else:
            lines.append(masker.mask(number, raw))
    if masker.open is not None:
        masker.problems.append((masker.open, "unterminated comment: '/*' is never closed by '*/'"))
    return lines, masker.problems
