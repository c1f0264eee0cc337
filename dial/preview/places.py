"""Where things are written: a program statement's line in its world file, a run's place.

World files are TOML, which keeps no line numbers, so a program's key is looked for in the
text: in the world file itself, then in the files it ``extends`` (the later ones first, as
they win a merge).
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

from dial.scene.resolve import resolve_scene

_TABLE = re.compile(r"^\s*\[\s*([^\[\]]+?)\s*\]\s*(#.*)?$")
_EXTENDS = re.compile(r"^\s*(extends|\"extends\")\s*=")


@dataclass(frozen=True)
class Place:
    """A run's place in a script, and its event: ``FILE:LINE:COL``."""

    path: str
    line: int
    col: int
    event: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line}:{self.col}"


def statement_place(world: Path, program: str, line: int) -> str | None:
    """``FILE:LINE`` of line ``line`` of ``program`` in the world file that defines it."""
    return Places().statement(world, program, line)


class Places:
    """Statement places, the files read once: a preview's (a file edited between two
    previews in one process is read afresh)."""

    def __init__(self) -> None:
        self._chains: dict[Path, tuple[Path, ...]] = {}
        self._texts: dict[Path, list[str] | None] = {}
        self._keys: dict[tuple[Path, str], tuple[int, bool] | None] = {}
        self._resolved: dict[Path, Path] = {}

    def statement(self, world: Path, program: str, line: int) -> str | None:
        """``FILE:LINE`` of line ``line`` of ``program`` in the world file that defines it."""
        if world not in self._resolved:
            self._resolved[world] = world.resolve()
        for path in self._chain(self._resolved[world]):
            if (path, program) not in self._keys:
                self._keys[path, program] = self._program_line(path, program)
            found = self._keys[path, program]
            if found is not None:
                key_line, inline = found
                return f"{path.name}:{key_line + line - (1 if inline else 0)}"
        return None

    def _chain(self, path: Path) -> tuple[Path, ...]:
        """The file, then the files it extends (transitively), later bases first."""
        if path in self._chains:
            return self._chains[path]
        self._chains[path] = (path,)  # an extends cycle ends here (the loader reports it)
        data = _extends(self._lines(path) or [])
        names = data.get("extends", [])
        names = [names] if isinstance(names, str) else names
        out = [path]
        for name in reversed(names if isinstance(names, list) else []):
            try:
                base = resolve_scene(str(name), path.parent).resolve()
            except LookupError:
                continue
            out += [p for p in self._chain(base) if p not in out]
        self._chains[path] = tuple(out)
        return self._chains[path]

    def _lines(self, path: Path) -> list[str] | None:
        if path not in self._texts:
            try:
                self._texts[path] = path.read_text(encoding="utf-8").splitlines()
            except (OSError, UnicodeDecodeError):
                self._texts[path] = None
        return self._texts[path]

    def _program_line(self, path: Path, program: str) -> tuple[int, bool] | None:
        """The line of ``program``'s key, and whether its first statement is on that line."""
        key = re.compile(
            rf"^\s*(?:programs\s*\.\s*)?(?:{re.escape(program)}|\"{re.escape(program)}\")\s*=\s*(.*)$"
        )
        table = ""
        for number, text in enumerate(self._lines(path) or [], start=1):
            header = _TABLE.match(text)
            if header is not None:
                table = header.group(1).replace(" ", "")
                continue
            match = key.match(text)
            dotted = text.lstrip().startswith("programs")
            if match is not None and (table == "programs" or (table == "" and dotted)):
                value = match.group(1)
                for quote in ('"""', "'''"):
                    if value.startswith(quote):
                        return number, bool(value[3:].strip())
                return number, True
        return None


def _extends(lines: list[str]) -> dict[str, object]:
    """The top-level ``extends`` of a world file's lines, as TOML reads it (``{}`` if none).

    Top-level keys come before the first table, so only those lines are read; an array
    value may span lines.
    """
    for i, text in enumerate(lines):
        if _TABLE.match(text):
            return {}
        if _EXTENDS.match(text):
            for j in range(i + 1, len(lines) + 1):  # the value may span lines
                try:
                    return tomllib.loads("\n".join(lines[i:j]))
                except tomllib.TOMLDecodeError:
                    continue
            return {}
    return {}
