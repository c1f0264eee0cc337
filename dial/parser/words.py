"""Tokenise the parameter part of definition and directive lines.

Parameters are whitespace-separated: a bare word, a double-quoted group (whose
words count one by one, as in the paper's ``"0x0666_0x0222 400"``), or
``key=value`` where the value may be quoted.
"""

from __future__ import annotations

import re

from dial.errors import Span
from dial.parser.ast import Param, Word

_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_]*$")
_WORD = re.compile(r"[^\s]+")


class WordError(Exception):
    """A malformed parameter; ``known`` if the scanner has reported it already."""

    def __init__(self, span: Span, message: str, known: bool = False) -> None:
        super().__init__(message)
        self.span = span
        self.message = message
        self.known = known


def _split_words(line: int, text: str, offset: int) -> tuple[Word, ...]:
    return tuple(
        Word(m.group(), Span(line, offset + m.start() + 1, offset + m.end() + 1))
        for m in _WORD.finditer(text)
    )


def tokenize(line: int, code: str, start: int) -> list[Param]:
    """Split ``code[start:]`` (comments already blanked) into parameters.

    Raises :class:`WordError` at the first malformed parameter.
    """
    if '"' not in code and "=" not in code:  # bare words only, as most directives have
        out: list[Param] = []
        for m in _WORD.finditer(code, start):
            span = Span(line, m.start() + 1, m.end() + 1)
            out.append(Param(None, (Word(m.group(), span),), False, span))
        return out
    params: list[Param] = []
    i = start
    n = len(code)
    while i < n:
        if code[i].isspace():
            i += 1
            continue
        begin = i
        key: str | None = None
        # A key=value pair: the key runs up to the first '=' of the token.
        j = i
        while j < n and not code[j].isspace() and code[j] not in '="':
            j += 1
        if j < n and code[j] == "=":
            key = code[i:j]
            if not _KEY.match(key):
                raise WordError(
                    Span(line, i + 1, j + 2),
                    f"expected key=value with a name before '=', got '{code[i : j + 1]}'",
                )
            i = j + 1
            if i >= n or code[i].isspace():
                raise WordError(Span(line, begin + 1, i + 1), f"missing value after '{key}='")
        if code[i] == '"':
            close = code.find('"', i + 1)
            if close < 0:
                raise WordError(Span(line, i + 1, n + 1), "unterminated string", known=True)
            words = _split_words(line, code[i + 1 : close], i + 1)
            end = close + 1
            if end < n and not code[end].isspace():
                raise WordError(
                    Span(line, end + 1, end + 2),
                    f"expected a space after the closing quote, got '{code[end]}'",
                )
            params.append(Param(key, words, True, Span(line, begin + 1, end + 1)))
            i = end
            continue
        end = i
        while end < n and not code[end].isspace():
            if code[end] == '"':
                raise WordError(
                    Span(line, end + 1, end + 2),
                    "unexpected '\"' inside a word: quote the whole parameter",
                )
            end += 1
        word = Word(code[i:end], Span(line, i + 1, end + 1))
        params.append(Param(key, (word,), False, Span(line, begin + 1, end + 1)))
        i = end
    return params
