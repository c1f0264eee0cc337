"""The dataset's files on disk: its layout, temporary names, atomic renames and the lock.

A writer writes every file of a session under a temporary name (``.NAME.tmp``, which
LeRobot's reader never globs) and renames it into place at a commit: ``meta/info.json``
last, since its totals are what the reader trusts. A lock file (``fcntl.flock``, released by
the system if the process dies) keeps two writers out of one folder.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Iterator
from contextlib import suppress
from pathlib import Path
from typing import IO

INFO = "meta/info.json"
STATS = "meta/stats.json"
TASKS = "meta/tasks.parquet"
META = (INFO, STATS, TASKS)
CHUNK_FILE = "chunk-{chunk:03d}/file-{file:03d}"
DATA = "data/" + CHUNK_FILE + ".parquet"
EPISODES = "meta/episodes/" + CHUNK_FILE + ".parquet"
VIDEO = "videos/{key}/" + CHUNK_FILE + ".mp4"
LOCK = ".dial-writing.lock"
_SLOT = re.compile(r"chunk-(\d+)/file-(\d+)\.\w+$")

# LeRobot's paths in info.json, with its own placeholders.
DATA_PATH = "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
VIDEO_PATH = "videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4"


def temporary(path: Path) -> Path:
    """Where ``path`` is written until its commit: hidden, and not ``*.parquet``."""
    return path.with_name(f".{path.name}.tmp")


def next_slot(folder: Path, chunks_size: int) -> tuple[int, int]:
    """The (chunk, file) after the last committed file under ``folder``; (0, 0) if none."""
    found = [
        (int(m.group(1)), int(m.group(2)))
        for p in folder.glob("chunk-*/file-*.*")
        if (m := _SLOT.search(p.as_posix())) is not None
    ]
    if not found:
        return 0, 0
    return following(max(found), chunks_size)


def following(slot: tuple[int, int], chunks_size: int) -> tuple[int, int]:
    """The next (chunk, file): a chunk holds ``chunks_size`` files, as LeRobot's writer does."""
    chunk, file = slot
    return (chunk + 1, 0) if file == chunks_size - 1 else (chunk, file + 1)


def stale(root: Path) -> Iterator[Path]:
    """Temporary files a dead writer left behind (safe to remove under the lock)."""
    for folder in ("data", "meta", "videos"):
        yield from (root / folder).rglob(".*.tmp")
    yield from root.glob(".*.tmp")


def write_json(path: Path, data: object, indent: int | None = 4) -> Path:
    """Write ``data`` as JSON under the temporary name of ``path``; return that name.
    (``indent=None`` writes one line, with the C encoder: stats of a tactile array are
    tens of thousands of numbers.)"""
    tmp = temporary(path)
    tmp.parent.mkdir(parents=True, exist_ok=True)
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(json.dumps(data, indent=indent) + "\n")
    return tmp


def read_json(path: Path) -> dict[str, object]:
    with open(path, encoding="utf-8") as f:
        data = json.load(f)
    if not isinstance(data, dict):
        raise ValueError(f"{path.name} is not a JSON object")
    return data


class Lock:
    """An exclusive lock on a dataset folder, held by this process while it writes."""

    def __init__(self, root: Path) -> None:
        self.path = root / LOCK
        self.file: IO[str] | None = open(self.path, "a", encoding="utf-8")  # noqa: SIM115
        try:
            import fcntl
        except ImportError:  # no flock (Windows): one writer at a time is up to the user
            return
        try:
            fcntl.flock(self.file.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self.file.close()
            self.file = None
            raise BlockingIOError(f"another process is writing '{root}'") from None

    def release(self) -> None:
        if self.file is not None:
            with suppress(OSError):
                self.path.unlink()
            self.file.close()
            self.file = None


def remove(paths: list[Path]) -> None:
    """Remove files, ignoring those already gone (a rollback)."""
    for path in paths:
        with suppress(OSError):
            path.unlink()


def prune(folder: Path, stop: Path) -> None:
    """Remove ``folder`` and its parents up to (not including) ``stop`` while they are empty."""
    while folder != stop and stop in folder.parents:
        try:
            folder.rmdir()
        except OSError:
            return
        folder = folder.parent


def size(path: Path) -> int:
    try:
        return os.stat(path).st_size
    except OSError:
        return 0
