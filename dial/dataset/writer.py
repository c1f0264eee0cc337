"""Write episodes into a LeRobot v3.0 dataset folder, streaming, with no reader needed.

    with DatasetWriter("demos", fps=50) as writer:
        for seed in range(10):
            dial.run("pour.dial", perturb=10, seed=seed, dataset=writer)

Frames go into ``data/chunk-CCC/file-FFF.parquet`` (one row group per episode), one file
until it would pass the size limit, as LeRobot's writer rolls its files over; each episode's
row (with its stats) into ``meta/episodes/``; the aggregate stats, the tasks and the totals
into ``meta/``. Memory holds one episode and the running aggregate, whatever the number of
episodes. Files are written under temporary names and renamed at a commit: when a data file
is full, and at :meth:`DatasetWriter.close`. A failed write (a full disk) rolls the folder
back to its last commit, so no half-written episode is ever left behind.
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Mapping
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from dial.dataset import files, tables
from dial.dataset.episode import Episode
from dial.dataset.features import FeatureJSON, all_features, check_fps, difference
from dial.dataset.meta import Totals, info_json, read_existing
from dial.dataset.stats import FeatureStats, as_json, episode_stats, merge
from dial.dataset.tables import DatasetError

DEFAULT_FILE_MB = 100.0  # LeRobot's default data file size
CHUNKS_SIZE = 1000  # files per chunk folder, as LeRobot's
ROWS_PER_GROUP = 50  # episode rows per row group of meta/episodes/


@dataclass
class _Committed:
    """What the folder holds as of the last commit (a rollback's target)."""

    episodes: int
    frames: int
    tasks: tuple[str, ...]
    stats: FeatureStats | None
    features: dict[str, FeatureJSON] | None


class _Open:
    """The data and episodes files a session is writing, under temporary names."""

    def __init__(self, root: Path, data: tuple[int, int], meta: tuple[int, int]) -> None:
        pa = tables.pa
        self.data_slot, self.meta_slot = data, meta
        self.data_path = root / files.DATA.format(chunk=data[0], file=data[1])
        self.meta_path = root / files.EPISODES.format(chunk=meta[0], file=meta[1])
        self.written: list[tuple[Path, Path]] = []  # (temporary, final), videos included
        for path in (self.data_path, self.meta_path):
            path.parent.mkdir(parents=True, exist_ok=True)
            self.written.append((files.temporary(path), path))
        self.sink = pa.OSFile(str(files.temporary(self.data_path)), "wb")
        self.data: Any = None  # ParquetWriters, made with the first episode's schemas
        self.meta: Any = None
        self.rows: list[Any] = []  # episode rows not yet written (one-row Arrow tables)
        self.frames = 0

    def add_row(self, row: Any) -> None:
        """Buffer an episode's row; write them ROWS_PER_GROUP at a time. (A row group's
        metadata, kept by the writer until the file closes, is about 0.1 MB for the
        episodes table's 150 columns: one per episode grew memory with the episodes.)"""
        self.rows.append(row)
        if len(self.rows) == ROWS_PER_GROUP:
            self.flush()

    def flush(self) -> None:
        if self.rows:
            self.meta.write_table(tables.pa.concat_tables(self.rows))
            self.rows.clear()

    def close(self) -> None:
        if self.meta is not None:
            self.flush()
        for writer in (self.data, self.meta):
            if writer is not None:
                writer.close()
        self.sink.close()

    def abandon(self) -> None:
        with suppress(Exception):
            self.close()
        files.remove([tmp for tmp, _ in self.written])


class DatasetWriter:
    """A LeRobot v3.0 dataset folder, open for appending episodes (see the module's doc).

    ``root`` is created if need be. An existing dataset must have the same fps and, at the
    first :meth:`add` (or :meth:`check`), the same features; anything else in the folder is
    an error. ``file_mb`` is the data files' size limit (default: the dataset's, else 100).
    info.json's ``robot_type`` is the robot of the episodes added (their profile's name; the
    dataset's, else ``robot_type``, until one is added).
    """

    def __init__(
        self,
        root: str | Path,
        *,
        fps: int = 50,
        file_mb: float | None = None,
        robot_type: str = "utah_hand_puma",
    ) -> None:
        check_fps(fps)
        tables.require()
        self.root, self.fps, self.robot_type = Path(root), fps, robot_type
        if self.root.exists() and not self.root.is_dir():
            raise DatasetError(f"cannot write the dataset: '{root}' is a file")
        self._made = next((p for p in [self.root, *self.root.parents] if p.exists()), None)
        try:
            self.root.mkdir(parents=True, exist_ok=True)
            self._lock = files.Lock(self.root)
        except OSError as e:
            self._unmake()
            raise DatasetError(f"cannot write the dataset '{root}': {e.strerror or e}") from None
        try:
            existing = read_existing(self.root, fps)
        except BaseException:
            self._lock.release()
            self._unmake()
            raise
        self.features: dict[str, FeatureJSON] | None = existing.features
        self.robot_type = existing.robot_type or robot_type
        self.file_bytes = int((file_mb or existing.file_mb or DEFAULT_FILE_MB) * 2**20)
        self.chunks_size = existing.chunks_size or CHUNKS_SIZE
        self._state = _Committed(
            existing.episodes, existing.frames, existing.tasks, existing.stats, existing.features
        )
        self.episodes, self.frames = existing.episodes, existing.frames
        self.tasks, self.stats = list(existing.tasks), existing.stats
        self.added = 0  # episodes added by this writer (committed or not)
        self.last_frames = 0  # the frames of the last episode added
        self._slots = self._first_slots()
        self._open: _Open | None = None
        self._video_slots: dict[str, tuple[int, int]] = {}
        self._closed = False

    def _first_slots(self) -> tuple[tuple[int, int], tuple[int, int]]:
        for path in files.stale(self.root):  # a dead writer's: the lock is ours
            files.remove([path])
        data = files.next_slot(self.root / "data", self.chunks_size)
        meta = files.next_slot(self.root / "meta" / "episodes", self.chunks_size)
        return data, meta

    # -- the public interface -------------------------------------------------------------------
    def check(self, features: Mapping[str, FeatureJSON]) -> None:
        """Raise a one-line :class:`DatasetError` if episodes with these data features (as
        :class:`~dial.dataset.episode.Episode` holds them) cannot go into this dataset."""
        wanted = all_features(dict(features))
        if self.features is None:
            return
        why = difference(self.features, wanted)
        if why is not None:
            raise DatasetError(f"cannot append to the dataset '{self.root}': {why}")

    def add(self, episode: Episode) -> int:
        """Write one episode; return its index. On a failed write the folder is rolled back
        to its last commit and a one-line :class:`DatasetError` says what was lost."""
        if self._closed:
            raise DatasetError(f"the dataset writer of '{self.root}' is closed")
        problem = episode.problem()
        if episode.fps != self.fps:
            problem = f"the episode is at {episode.fps} fps, the dataset at {self.fps}"
        if problem is not None:
            raise DatasetError(f"cannot write to the dataset '{self.root}': {problem}")
        self.check(episode.features)
        with self._or_rollback():
            return self._write(episode)

    def close(self) -> None:
        """Commit what was added, and let the folder go; idempotent. A new dataset that got
        no episode leaves no folder behind."""
        if self._closed:
            return
        try:
            self.commit()
        finally:
            self._closed = True
            self._release()

    def __enter__(self) -> DatasetWriter:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, e: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()  # every episode added is whole: keep them, whatever stopped the loop

    # -- writing --------------------------------------------------------------------------------
    def _write(self, episode: Episode) -> int:
        n, index = episode.length, self.episodes
        if self._open is not None and self._full(n):
            self.commit()  # before this episode's task is known: it goes with the episode
        if self.features is None:
            self.features = all_features(dict(episode.features))
        self.robot_type = episode.robot_type
        if episode.task not in self.tasks:
            self.tasks.append(episode.task)
        task = self.tasks.index(episode.task)
        if self._open is None:
            self._open = _Open(self.root, *self._slots)
        out = self._open
        table = tables.frames_table(
            self.features, episode.columns, self.fps, index, self.frames, task
        )
        stats = episode_stats({**episode.columns, **_index_columns(table)})
        stats.update({k: dict(v) for k, v in episode.video_stats.items()})
        if out.data is None:
            out.data = tables.pa.parquet.ParquetWriter(out.sink, table.schema, compression="snappy")
        out.data.write_table(table, row_group_size=n)
        row = self._row(episode, index, task, stats, out)
        if out.meta is None:
            schema = tables.episodes_schema(stats, sorted(episode.videos))
            path = str(files.temporary(out.meta_path))
            out.meta = tables.pa.parquet.ParquetWriter(path, schema, compression="snappy")
        out.add_row(tables.episode_row(out.meta.schema, row))
        out.frames += n
        self.stats = merge(self.stats, stats)
        self.episodes, self.frames, self.added = index + 1, self.frames + n, self.added + 1
        self.last_frames = n
        return index

    def _full(self, frames: int) -> bool:
        """Whether ``frames`` more would take the open data file past its limit (LeRobot's
        rule: its size so far plus that many frames at its mean size per frame)."""
        out = self._open
        if out is None or out.frames == 0:
            return False
        size = out.sink.tell()
        return bool(size + size / out.frames * frames >= self.file_bytes)

    def _row(
        self, episode: Episode, index: int, task: int, stats: FeatureStats, out: _Open
    ) -> dict[str, object]:
        row: dict[str, object] = {
            "episode_index": index,
            "tasks": [self.tasks[task]],
            "length": episode.length,
            "data/chunk_index": out.data_slot[0],
            "data/file_index": out.data_slot[1],
            "dataset_from_index": self.frames,
            "dataset_to_index": self.frames + episode.length,
            "meta/episodes/chunk_index": out.meta_slot[0],
            "meta/episodes/file_index": out.meta_slot[1],
        }
        for key, video in sorted(episode.videos.items()):
            chunk, file = self._video_file(key, video, out)
            row[f"videos/{key}/chunk_index"] = chunk
            row[f"videos/{key}/file_index"] = file
            row[f"videos/{key}/from_timestamp"] = 0.0
            row[f"videos/{key}/to_timestamp"] = episode.length / self.fps
        for name, feature in stats.items():
            for key, values in feature.items():
                row[f"stats/{name}/{key}"] = values
        row.update(episode.info.columns())
        return row

    def _video_file(self, key: str, video: bytes, out: _Open) -> tuple[int, int]:
        """One mp4 per episode and camera (LeRobot's reader seeks by the episode's
        timestamps within a file; a file of its own starts at 0)."""
        slot = self._video_slots.get(key)
        if slot is None:
            slot = files.next_slot(self.root / "videos" / key, self.chunks_size)
        path = self.root / files.VIDEO.format(key=key, chunk=slot[0], file=slot[1])
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = files.temporary(path)
        out.written.append((tmp, path))
        tmp.write_bytes(video)
        self._video_slots[key] = files.following(slot, self.chunks_size)
        return slot

    # -- commits and rollbacks ------------------------------------------------------------------
    def commit(self) -> None:
        """Close the open files and rename everything into place, ``meta/info.json`` last."""
        out = self._open
        if out is None:
            self._unmake_if_empty()
            return
        with self._or_rollback():
            out.close()
            info, stats, tasks = (self.root / p for p in files.META)
            written = [*out.written, (files.temporary(tasks), tasks)]
            tables.pa.parquet.write_table(tables.tasks_table(self.tasks), str(written[-1][0]))
            stats_json = as_json(self.stats or {})
            written.append((files.write_json(stats, stats_json, indent=None), stats))
            totals = Totals(
                self.fps,
                self.episodes,
                self.frames,
                len(self.tasks),
                self.chunks_size,
                self.file_bytes,
                self.robot_type,
            )
            info_text = info_json(self.features, totals)
            written.append((files.write_json(info, info_text), info))  # the last
            for tmp, final in written:
                tmp.replace(final)
        self._open = None
        data, meta = self._slots
        self._slots = (
            files.following(data, self.chunks_size),
            files.following(meta, self.chunks_size),
        )
        self._state = _Committed(
            self.episodes, self.frames, tuple(self.tasks), self.stats, self.features
        )

    @contextmanager
    def _or_rollback(self) -> Iterator[None]:
        """Whatever fails inside rolls the folder back to its last commit; a write error
        becomes a one-line DatasetError that says what was lost."""
        try:
            yield
        except BaseException as e:
            lost = self.episodes - self._state.episodes
            self.rollback()
            if isinstance(e, OSError | tables.pa.ArrowException):
                raise DatasetError(self._failure(e, lost)) from None
            raise

    def rollback(self) -> None:
        """Forget what was written since the last commit, on disk and here."""
        if self._open is not None:
            self._open.abandon()
            self._open = None
        files.remove(
            [files.temporary(self.root / p) for p in (files.INFO, files.STATS, files.TASKS)]
        )
        s = self._state
        self.episodes, self.frames, self.stats = s.episodes, s.frames, s.stats
        self.tasks, self.features = list(s.tasks), s.features
        self._video_slots.clear()
        self._unmake_if_empty()

    def _failure(self, e: BaseException, lost: int) -> str:
        text = getattr(e, "strerror", None) or str(e).strip() or type(e).__name__
        errno = re.search(r"\[errno \d+\] ([^\n]+)", text)  # pyarrow: "... Detail: [errno 28] ..."
        why = errno.group(1) if errno else text.splitlines()[0]
        kept = (
            f"it holds {self.episodes} episodes as before"
            if self.episodes
            else "nothing was written"
        )
        return (
            f"cannot write the dataset '{self.root}': {why}; the {lost} episode(s) written "
            f"since its last commit were removed, {kept}"
        )

    # -- the folder -----------------------------------------------------------------------------
    def _release(self) -> None:
        self._lock.release()
        self._unmake_if_empty()

    def _unmake_if_empty(self) -> None:
        if self.episodes == 0 and self._state.episodes == 0:
            for folder in ("data/chunk-*", "meta/episodes/chunk-*", "videos/*/chunk-*"):
                for path in self.root.glob(folder):
                    files.prune(path, self.root)
        self._unmake()

    def _unmake(self) -> None:
        """Remove the folders this writer made, while they are empty."""
        if self._made is not None and self._made != self.root:
            files.prune(self.root, self._made)


def _index_columns(table: Any) -> dict[str, NDArray[np.generic]]:
    return {name: table.column(name).to_numpy() for name in tables.index_names()}
