"""Where things are written: a program statement's line in its world file, a run's place.

World files are TOML, which keeps no line numbers, so a program's key is looked for in the
text: in the world file itself, then in the files it ``extends`` (the later ones first, as
they win a merge).
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from dial.scene.resolve import resolve_scene

_TABLE = re.compile(r"^\s*\[\s*([^\[\]]+?)\s*\]\s*(#.*)?$")


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
    for path in _chain(world.resolve()):
        found = _program_line(path, program)
        if found is not None:
            key_line, inline = found
            return f"{path.name}:{key_line + line - (1 if inline else 0)}"
    return None


@cache
def _chain(path: Path) -> tuple[Path, ...]:
    """The file, then the files it extends (transitively), later bases first."""
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError):
        return (path,)
    names = data.get("extends", [])
    names = [names] if isinstance(names, str) else names
    out = [path]
    for name in reversed(names if isinstance(names, list) else []):
        try:
            base = resolve_scene(str(name), path.parent).resolve()
        except LookupError:
            continue
        out += [p for p in _chain(base) if p not in out]
    return tuple(out)


@cache
def _program_line(path: Path, program: str) -> tuple[int, bool] | None:
    """The line of ``program``'s key, and whether its first statement is on that line."""
    key = re.compile(
        rf"^\s*(?:programs\s*\.\s*)?(?:{re.escape(program)}|\"{re.escape(program)}\")\s*=\s*(.*)$"
    )
    table = ""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return None
    for number, text in enumerate(lines, start=1):
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
