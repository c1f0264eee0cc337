"""A sweep's episodes, written in trial order as the trials finish in any order."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from dial.dataset.episode import Episode
    from dial.dataset.writer import DatasetWriter


class InOrder:
    """Holds an episode that finished early until those before it are written; with the
    trials started in order, a handful wait at most (``peak`` says how many did)."""

    def __init__(self, writer: DatasetWriter) -> None:
        self.writer = writer
        self.waiting: dict[int, Episode | None] = {}
        self.next = 0  # the trial whose episode is written next
        self.written = 0
        self.skipped = 0  # trials without an episode (failed, with --successful-only)
        self.peak = 0

    def put(self, k: int, episode: Episode | None) -> None:
        """Trial ``k``'s episode (None: it has none); write every one now in order."""
        self.waiting[k] = episode
        self.peak = max(self.peak, sum(e is not None for e in self.waiting.values()))
        while self.next in self.waiting:
            ready = self.waiting.pop(self.next)
            self.next += 1
            if ready is None:
                self.skipped += 1
            else:
                self.writer.add(ready)
                self.written += 1
