"""Tokenise the parameter part of definition and directive lines.

Parameters are whitespace-separated: a bare word, a double-quoted group (whose
words count one by one, as in the paper's ``"0x0666_0x0222 400"``), or
``key=value`` where the value may be quoted.
"""

from __future__ import annotations

import re
from dataclasses import fields

from dial.errors import Span
from dial.parser.ast import Param, Word

_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_]*$")
_WORD = re.compile(r"[^\s]+")
_SPACE = re.compile(r"\s*")
_HEAD = re.compile(r'[^\s="]*')  # up to a space, '=' or '"


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


def bare_words(line: int, code: str, start: int) -> list[Word] | None:
    """The words of ``code[start:]`` if it has no quote and no ``=``, else None."""
    if '"' in code or "=" in code:
        return None
    return [
        Word(m.group(), Span(line, m.start() + 1, m.end() + 1)) for m in _WORD.finditer(code, start)
    ]


def tokenize(line: int, code: str, start: int) -> list[Param]:
    """Split ``code[start:]`` (comments already blanked) into parameters.

    Raises :class:`WordError` at the first malformed parameter.
    """
    bare = bare_words(line, code, start)
    if bare is not None:
        return [Param(None, (w,), False, w.span) for w in bare]
    if code.find('"', start) < 0:
        return _unquoted(line, code, start)
    return _general(line, code, start)


def _general(line: int, code: str, start: int) -> list[Param]:
    """:func:`tokenize` of any parameters, quoted groups included."""
    params: list[Param] = []
    n = len(code)
    i = _SPACE.match(code, start).end()  # type: ignore[union-attr]  # matches empty too
    while i < n:
        begin = i
        key: str | None = None
        # A key=value pair: the key runs up to the first '=' of the token.
        head = _HEAD.match(code, i).end()  # type: ignore[union-attr]
        if head < n and code[head] == "=":
            key = code[i:head]
            if not _KEY.match(key):
                raise WordError(
                    Span(line, i + 1, head + 2),
                    f"expected key=value with a name before '=', got '{code[i : head + 1]}'",
                )
            i = head + 1
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
        else:
            end = _WORD.match(code, i).end()  # type: ignore[union-attr]  # code[i] is no space
            quote = code.find('"', i, end)
            if quote >= 0:
                raise WordError(
                    Span(line, quote + 1, quote + 2),
                    "unexpected '\"' inside a word: quote the whole parameter",
                )
            word = Word(code[i:end], Span(line, i + 1, end + 1))
            params.append(Param(key, (word,), False, Span(line, begin + 1, end + 1)))
        i = _SPACE.match(code, end).end()  # type: ignore[union-attr]
    return params


def _unquoted(line: int, code: str, start: int) -> list[Param]:
    """:func:`tokenize` of parameters without quotes: each word is a bare word or
    ``key=value`` (the value up to the next space, ``=`` included). Lean, as a 300 KB line
    of parameters is 75,000 of them (issue 26): spans are made as plain tuples are, and
    words and parameters by setting their slots (``tests/test_properties.py`` holds this
    path to :func:`_general`'s results)."""
    params: list[Param] = []
    append, span = params.append, tuple.__new__
    for m in _WORD.finditer(code, start):
        text = m.group()
        begin, end = m.span()
        eq = text.find("=")
        if eq < 0:
            at = span(Span, (line, begin + 1, end + 1))
            append(_param(None, _word(text, at), at))
            continue
        key = text[:eq]
        if not _KEY.match(key):
            raise WordError(
                Span(line, begin + 1, begin + eq + 2),
                f"expected key=value with a name before '=', got '{text[: eq + 1]}'",
            )
        if eq == len(text) - 1:
            raise WordError(Span(line, begin + 1, end + 1), f"missing value after '{key}='")
        word = _word(text[eq + 1 :], span(Span, (line, begin + eq + 2, end + 1)))
        append(_param(key, word, span(Span, (line, begin + 1, end + 1))))
    return params


# A Word and an unquoted Param without their dataclass __init__ (a Python frame and a
# generic setattr per field): their slots are set through the slots' own descriptors.
assert [f.name for f in fields(Word)] == ["text", "span"]
assert [f.name for f in fields(Param)] == ["key", "words", "quoted", "span"]
_NEW = object.__new__
_TEXT, _SPAN = (Word.__dict__[name].__set__ for name in ("text", "span"))
_KEY_OF, _WORDS, _QUOTED, _PARAM_SPAN = (
    Param.__dict__[name].__set__ for name in ("key", "words", "quoted", "span")
)


def _word(text: str, at: Span) -> Word:
    word: Word = _NEW(Word)
    _TEXT(word, text)
    _SPAN(word, at)
    return word


def _param(key: str | None, word: Word, at: Span) -> Param:
    param: Param = _NEW(Param)
    _KEY_OF(param, key)
    _WORDS(param, (word,))
    _QUOTED(param, False)
    _PARAM_SPAN(param, at)
    return param
