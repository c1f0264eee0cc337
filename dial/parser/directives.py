"""The arguments of directives: counts, conditions, loop and retry limits, abort messages.

Each reader reports its problem through ``error`` and returns None, so that the parser
keeps the directive's block structure even when its arguments are bad.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Literal

from dial.errors import Span, shorten
from dial.parser.ast import Condition, Param, Word

_COND = re.compile(r"(!?)([A-Za-z_][A-Za-z0-9_]*)$")
DEFAULT_MAX = 100
MAX_COUNT = 1_000_000
DEFAULT_RETRY = 3
MAX_RETRY = 100

RepeatSpec = tuple[Literal["count", "until", "while"], int, Condition | None]
OnError = Callable[[Span, str], None]  # reports a problem at a span


def arity(error: OnError, span: Span, name: str, words: list[Word], n: int, form: str) -> bool:
    """Whether ``@name`` has ``n`` words; otherwise report ``form`` under the extra ones."""
    if len(words) == n:
        return True
    where = words[n].span.to(words[-1].span) if len(words) > n else span
    error(where, f"'@{name}' takes {form}")
    return False


def condition(error: OnError, word: Word) -> Condition | None:
    m = _COND.match(word.text)
    if m is None:
        error(word.span, f"expected a condition EVENT or !EVENT, got '{word.text}'")
        return None
    return Condition(m.group(2), m.group(1) == "!", word.span)


def count(error: OnError, word: Word, what: str, hi: int) -> int | None:
    """A whole number from 1 to ``hi`` in ASCII digits."""
    text = word.text
    if (
        not (text.isascii() and text.isdigit())
        or len(text) > len(str(hi))
        or not 1 <= int(text) <= hi
    ):
        error(word.span, f"expected {what}, got '{shorten(text)}'")
        return None
    return int(text)


def repeat_spec(
    error: OnError, span: Span, line_span: Span, words: list[Word]
) -> RepeatSpec | None:
    """``@repeat N`` or ``@repeat until|while COND [max N]``."""
    form = "N, or until/while COND [max N]"
    if not words:
        error(span, f"'@repeat' takes {form}")
        return None
    head = words[0].text
    if head not in ("until", "while"):
        if not arity(error, span, "repeat", words, 1, form):
            return None
        n = count(
            error, words[0], f"a repeat count from 1 to {MAX_COUNT}, until or while", MAX_COUNT
        )
        return None if n is None else ("count", n, None)
    if len(words) not in (2, 4) or (len(words) == 4 and words[2].text != "max"):
        error(line_span, f"'@repeat' takes {form}")
        return None
    cond = condition(error, words[1])
    limit = (
        count(error, words[3], f"a loop limit from 1 to {MAX_COUNT}", MAX_COUNT)
        if len(words) == 4
        else DEFAULT_MAX
    )
    if cond is None or limit is None:
        return None
    return ("until" if head == "until" else "while", limit, cond)


def one_condition(error: OnError, span: Span, name: str, words: list[Word]) -> Condition | None:
    """``@if COND`` or ``@on COND``."""
    form = f"one condition: @{name} EVENT or @{name} !EVENT"
    if not arity(error, span, name, words, 1, form):
        return None
    return condition(error, words[0])


def retry_max(error: OnError, span: Span, words: list[Word]) -> int | None:
    """``@retry [max N]``: the retry limit."""
    if not words:
        return DEFAULT_RETRY
    if len(words) != 2 or words[0].text != "max":
        error(words[0].span.to(words[-1].span), "'@retry' takes nothing or 'max N': @retry [max N]")
        return None
    return count(error, words[1], f"a retry limit from 1 to {MAX_RETRY}", MAX_RETRY)


def abort_message(error: OnError, span: Span, params: list[Param]) -> str | None:
    """``@abort "MESSAGE"``: the message, one quoted string."""
    if len(params) != 1 or not params[0].quoted or not params[0].words:
        where = params[0].span.to(params[-1].span) if params else span
        error(where, "'@abort' takes one quoted message: @abort \"MESSAGE\"")
        return None
    return " ".join(w.text for w in params[0].words)


MAX_NAME_BYTES = 255  # one file or directory name, as file systems allow
MAX_PATH_BYTES = 1024


def file_path(error: OnError, word: Word, what: str) -> bool:
    """Whether ``word`` can name a file (if not, reported): no control character, and
    within the length that file systems allow."""
    text = word.text
    bad = next((i for i, ch in enumerate(text) if ord(ch) < 32 or ord(ch) == 127), None)
    if bad is not None:
        code = f"U+{ord(text[bad]):04X}" + (" (NUL)" if text[bad] == "\0" else "")
        error(
            Span.at(word.span.line, word.span.col + bad),
            f"{what} holds the control character {code}",
        )
        return False
    if len(text.encode()) > MAX_PATH_BYTES:
        error(word.span, f"{what} is {len(text.encode())} bytes long; at most {MAX_PATH_BYTES}")
        return False
    long = next((p for p in text.split("/") if len(p.encode()) > MAX_NAME_BYTES), None)
    if long is not None:
        error(
            word.span,
            f"{what} has a name of {len(long.encode())} bytes ('{long[:20]}...'); file names "
            f"are at most {MAX_NAME_BYTES}",
        )
        return False
    return True
