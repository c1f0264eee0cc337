"""Where each key and value of a TOML file is: line and column, for messages that point.

:mod:`tomllib` gives values without positions. :func:`locate` walks the same text again and
records, for every key path (``("fingers", 0, "joints", 2)``: tables and keys by name, array
elements and ``[[array]]`` tables by index), the place of its value. It reads the TOML that
:mod:`tomllib` accepted, so it assumes the text is valid; on anything it does not follow it
stops, and the places it has found stay good.
"""

from __future__ import annotations

import re
from contextlib import suppress

from dial.errors import Span

Path = tuple[str | int, ...]

_BARE = re.compile(r"[A-Za-z0-9_-]+")
_ATOM = re.compile(r"[^\s,\]\}#]+")  # a number, a boolean or a date: up to a separator


class _Stop(Exception):
    """The text is not what the walk expected: keep what was found."""


class _Walker:
    def __init__(self, text: str) -> None:
        self.text = text
        self.i = 0
        self.found: dict[Path, Span] = {}
        self.counts: dict[Path, int] = {}  # [[array]] tables seen so far, by path

    def span(self, start: int, end: int) -> Span:
        """From ``start`` to ``end``, cut at the end of the first line (a caret spans one)."""
        line_end = self.text.find("\n", start)
        end = min(end, len(self.text) if line_end < 0 else line_end)
        col = start - (self.text.rfind("\n", 0, start) + 1) + 1
        return Span.at(self.text.count("\n", 0, start) + 1, col, end - start)

    def skip(self, newlines: bool = True) -> None:
        """Past blanks and comments (and newlines, if asked)."""
        while self.i < len(self.text):
            c = self.text[self.i]
            if c == "#":
                end = self.text.find("\n", self.i)
                self.i = len(self.text) if end < 0 else end
            elif c in " \t\r" or (newlines and c == "\n"):
                self.i += 1
            else:
                return

    def key(self) -> list[str]:
        parts = []
        while True:
            self.skip(newlines=False)
            parts.append(self.simple_key())
            self.skip(newlines=False)
            if self.text.startswith(".", self.i):
                self.i += 1
                continue
            return parts

    def simple_key(self) -> str:
        if self.text.startswith(('"', "'"), self.i):
            start = self.i
            self.string()
            return self.text[start + 1 : self.i - 1]
        m = _BARE.match(self.text, self.i)
        if not m:
            raise _Stop
        self.i = m.end()
        return m.group()

    def string(self) -> None:
        t, i = self.text, self.i
        for quote in ('"""', "'''", '"', "'"):
            if t.startswith(quote, i):
                j = i + len(quote)
                while True:
                    k = t.find(quote, j)
                    if k < 0:
                        raise _Stop
                    if quote[0] == '"' and _escaped(t, k):
                        j = k + 1
                        continue
                    self.i = k + len(quote)
                    while len(quote) == 3 and t.startswith(quote[0], self.i):
                        self.i += 1  # """a"""" ends with a quote inside
                    return
        raise _Stop

    def value(self, path: Path) -> None:
        start = self.i
        t = self.text
        if t.startswith(("'", '"'), start):
            self.string()
        elif t.startswith("[", start):
            self.i += 1
            n = 0
            while True:
                self.skip()
                if t.startswith("]", self.i):
                    self.i += 1
                    break
                self.value((*path, n))
                n += 1
                self.skip()
                if t.startswith(",", self.i):
                    self.i += 1
        elif t.startswith("{", start):
            self.i += 1
            while True:
                self.skip(newlines=False)
                if t.startswith("}", self.i):
                    self.i += 1
                    break
                self.pair(path)
                self.skip(newlines=False)
                if t.startswith(",", self.i):
                    self.i += 1
        else:
            m = _ATOM.match(t, start)
            if not m:
                raise _Stop
            self.i = m.end()
        self.found[path] = self.span(start, self.i)

    def pair(self, table: Path) -> None:
        parts = self.key()
        if not self.text.startswith("=", self.i):
            raise _Stop
        self.i += 1
        self.skip(newlines=False)
        self.value((*table, *parts))

    def header(self) -> Path:
        start = self.i
        double = self.text.startswith("[[", self.i)
        self.i += 2 if double else 1
        parts: Path = tuple(self.key())
        self.i += 2 if double else 1
        if double:
            n = self.counts.get(parts, 0)
            self.counts[parts] = n + 1
            parts = (*parts, n)
        self.found.setdefault(parts, self.span(start, self.i))
        return parts

    def walk(self) -> None:
        table: Path = ()
        while True:
            self.skip()
            if self.i >= len(self.text):
                return
            if self.text.startswith("[", self.i):
                table = self.header()
            else:
                self.pair(table)


def _escaped(text: str, k: int) -> bool:
    backslashes = 0
    while k - backslashes - 1 >= 0 and text[k - backslashes - 1] == "\\":
        backslashes += 1
    return backslashes % 2 == 1


def locate(text: str) -> dict[Path, Span]:
    """The place of every key path's value (a table's: its ``[header]``) in valid TOML."""
    walker = _Walker(text)
    with suppress(_Stop):
        walker.walk()
    return walker.found


def nearest(found: dict[Path, Span], path: Path) -> Span:
    """The place of ``path``, else of its closest ancestor that has one, else line 1."""
    for n in range(len(path), 0, -1):
        if path[:n] in found:
            return found[path[:n]]
    return Span(1, 1, 2)
