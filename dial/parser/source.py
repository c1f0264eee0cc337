"""Split a script into physical lines, with comments masked out.

Comments are replaced by spaces rather than removed, so that every remaining
character keeps its column: columns are ticks in an execution line.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from dial.errors import Span

_NAME_START = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_")


class Kind(Enum):
    BLANK = "blank"
    COMMENT = "comment"
    DEFINITION = "definition"
    DIRECTIVE = "directive"
    EXECUTION = "execution"
    OTHER = "other"


@dataclass(frozen=True)
class Line:
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


def scan(text: str) -> tuple[list[Line], list[tuple[Span, str]]]:
    """Return the lines of ``text`` and any lexical problems (span, message)."""
    problems: list[tuple[Span, str]] = []
    lines: list[Line] = []
    in_comment: Span | None = None  # where the open /* started
    physical = text.split("\n")
    if physical and physical[-1] == "":
        physical.pop()
    for number, raw in enumerate(physical, start=1):
        raw = raw.removesuffix("\r")
        started_in_comment = in_comment is not None
        quotes = not started_in_comment and raw[:1] in ("%", "@")
        code = list(raw)
        comment_cols: list[int] = []
        i = 0
        in_quote: int | None = None
        while i < len(raw):
            ch = raw[i]
            if in_comment is not None:
                code[i] = " "
                if raw.startswith("*/", i):
                    code[i + 1] = " "
                    in_comment = None
                    i += 2
                    continue
                i += 1
                continue
            if in_quote is not None:
                if ch == '"':
                    in_quote = None
                i += 1
                continue
            if quotes and ch == '"':
                in_quote = i
            elif raw.startswith("//", i):
                comment_cols.append(i)
                for j in range(i, len(raw)):
                    code[j] = " "
                break
            elif raw.startswith("/*", i):
                comment_cols.append(i)
                in_comment = Span.at(number, i + 1, 2)
                code[i] = code[i + 1] = " "
                i += 2
                continue
            i += 1
        if in_quote is not None:
            problems.append(
                (
                    Span(number, in_quote + 1, len(raw) + 1),
                    "unterminated string: add a closing '\"'",
                )
            )
        masked = "".join(code)
        stripped = masked.rstrip()
        has_comment = started_in_comment or bool(comment_cols)
        comment_at = comment_cols[0] if len(comment_cols) == 1 else None
        foreign = (
            started_in_comment
            or in_comment is not None
            or len(comment_cols) > 1
            or (comment_at is not None and masked[comment_at:].strip() != "")
        )
        if not stripped:
            kind = Kind.COMMENT if has_comment else Kind.BLANK
        elif stripped[0] == "%":
            kind = Kind.DEFINITION
        elif stripped[0] == "@":
            kind = Kind.DIRECTIVE
        elif stripped[0] in _NAME_START:
            kind = Kind.EXECUTION
        else:
            kind = Kind.OTHER
        lines.append(Line(number, raw, masked, kind, has_comment, comment_at, foreign))
    if in_comment is not None:
        problems.append((in_comment, "unterminated comment: '/*' is never closed by '*/'"))
    return lines, problems
