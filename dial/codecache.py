"""The compiled code of dial's dataclasses, kept in the user's cache (docs/architecture.md,
"Start-up").

Python makes a dataclass's methods (``__init__``, ``__repr__``, ``__eq__``, ``__hash__``,
``__setattr__`` of a frozen one) by compiling their source text, each time a module is
imported: its bytecode cache does not hold them. dial makes about a hundred dataclasses
before a run's first tick, and that compiling is half of what importing dial's modules
costs. So :func:`install` has ``dataclasses`` compile through :func:`_exec`, which keeps
each text's code object, for dial's own modules alone, and a file of the user's cache
folder keeps them across processes.

The key of an entry is the whole source text, and the code object of a text is what
``compile`` makes of it, so an entry is either that very code or never looked up: an edited
dataclass makes another text. The file is named by what the code objects depend on besides
the text (Python's version, bytecode and marshal format, the optimization level), so another
Python reads another file. It is written at exit only if something new was compiled (as
the IK memo's: whole, renamed over the old one, at most :data:`MAX_SAVED` entries, this
process's last); an unreadable, damaged or foreign file is a miss, never an error; an entry
that is not a code object is not used. ``DIAL_CACHE=off``: nothing is installed.
"""

from __future__ import annotations

import atexit
import builtins
import dataclasses
import marshal
import sys
from contextlib import suppress
from importlib.util import MAGIC_NUMBER
from pathlib import Path
from types import CodeType

from dial import usercache

MAX_SAVED = 4000  # entries in the file (a hundred dataclasses make about 600)
_OWN = "dial."  # the modules whose dataclasses' code is kept


class CodeCache:
    """Code objects by source text: this process's, then those of the file ``path``."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._codes: dict[str, CodeType] | None = None  # the file's, read on first use
        self._used: dict[str, CodeType] = {}  # read or compiled in this process
        self._new = False

    def code(self, source: str) -> CodeType:
        """``compile(source)`` as ``exec`` would: with the file name ``<string>`` and no
        compiler flags of this module (its ``from __future__ import annotations``)."""
        found = self._used.get(source)
        if found is not None:
            return found
        if self._codes is None:
            self._codes = _read(self.path)
        found = self._codes.get(source)
        if type(found) is not CodeType:  # a miss, or an entry this module did not write
            found = _compiled(source)
            self._new = True
        self._used[source] = found
        return found

    def save(self) -> None:
        """Merge this process's entries into the file, if it compiled anything new."""
        if not self._new:
            return
        self._new = False
        old = _read(self.path)
        merged = {k: v for k, v in old.items() if k not in self._used and _kept(k, v)}
        merged.update(self._used)
        keep = dict(list(merged.items())[-MAX_SAVED:])
        with suppress(OSError, ValueError):
            usercache.replace(self.path, marshal.dumps(keep))


def _read(path: Path) -> dict[str, CodeType]:
    try:
        found = marshal.loads(path.read_bytes())
    except (OSError, EOFError, ValueError, TypeError):
        return {}  # none yet, unreadable or damaged: compile again
    return found if isinstance(found, dict) else {}


def _kept(source: object, code: object) -> bool:
    """Whether an entry of the file is as :meth:`CodeCache.save` writes one."""
    return type(source) is str and type(code) is CodeType


def file_name() -> str:
    """The file's name: what a code object depends on besides its source text."""
    tag = sys.implementation.cache_tag or sys.implementation.name
    return f"dataclasses-{tag}-{MAGIC_NUMBER.hex()}-m{marshal.version}-O{sys.flags.optimize}"


_CACHE: list[CodeCache] = []  # the installed cache, if any


def installed() -> CodeCache | None:
    return _CACHE[0] if _CACHE else None


def install() -> None:
    """Have ``dataclasses`` compile dial's methods through the cache (once per process; not
    with ``DIAL_CACHE=off``, nor where ``dataclasses`` makes no methods from text)."""
    folder = usercache.folder("code")
    if _CACHE or folder is None or not hasattr(dataclasses, "_create_fn"):
        return
    cache = CodeCache(folder / f"{file_name()}.marshal")
    _CACHE.append(cache)
    # A global of the module shadows the built-in for dataclasses' own code alone.
    dataclasses.exec = _exec  # type: ignore[attr-defined]
    atexit.register(cache.save)


def _exec(
    source: object,
    namespace: dict[str, object] | None = None,
    local: dict[str, object] | None = None,
) -> None:
    """``exec(source, namespace, local)`` for ``dataclasses``: a text made for a class of
    dial's (``namespace`` is its module's) runs as the cached code object."""
    if isinstance(source, str):  # compiled here, it would take this module's future flags
        cache = installed()
        own = namespace is not None and str(namespace.get("__name__", "")).startswith(_OWN)
        made = cache.code(source) if cache is not None and own else _compiled(source)
        builtins.exec(made, namespace, local)
    else:
        builtins.exec(source, namespace, local)  # type: ignore[arg-type]


def _compiled(source: str) -> CodeType:
    """What ``exec(source)`` compiles in ``dataclasses`` (a module without future imports)."""
    return compile(source, "<string>", "exec", dont_inherit=True)
