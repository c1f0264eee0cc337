"""The user's cache folder, shared by dial's caches (docs/architecture.md, "Start-up").

``$DIAL_CACHE``, else the platform's user cache folder (``$XDG_CACHE_HOME/dial`` or
``~/.cache/dial`` on Linux); ``DIAL_CACHE=off`` turns every cache off. Each cache has a
folder of its own in it (``ik``, the IK's memo; ``code``, the dataclasses' code). A file is
replaced whole, so that a reader sees the old file or the new one, never a part.

Imports nothing heavy: ``import dial`` uses it.
"""

from __future__ import annotations

import os
import sys
import time
from contextlib import suppress
from pathlib import Path

STALE_DAYS = 30  # other files of a cache's folder untouched this long are removed on a write
_OFF = ("", "0", "off", "no", "none", "false")


def folder(name: str) -> Path | None:
    """The folder of the cache ``name`` (not made here); None when ``DIAL_CACHE`` turns the
    caches off."""
    chosen = os.environ.get("DIAL_CACHE")
    if chosen is not None:
        return None if chosen.strip().lower() in _OFF else Path(chosen) / name
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "dial" / name


def replace(path: Path, data: bytes) -> None:
    """Replace ``path`` whole (a reader sees the old file or the new one), then remove the
    folder's other files that nothing has written for :data:`STALE_DAYS`."""
    import tempfile  # only to write: ``import dial`` reads this module

    path.parent.mkdir(parents=True, exist_ok=True)
    fd, temp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(temp, path)
    except BaseException:
        with suppress(OSError):
            os.unlink(temp)
        raise
    stale = time.time() - STALE_DAYS * 86400
    for other in path.parent.iterdir():
        with suppress(OSError):
            if other != path and other.stat().st_mtime < stale:
                other.unlink()
