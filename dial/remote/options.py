"""``dial run --remote``'s options, as the operator's modules share them."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from dial.remote.link import LinkSpec

Progress = Callable[[int, float, list[str]], None]  # (tick, simulated s, running events)


@dataclass
class OperatorOptions:
    """``dial run --remote``'s options."""

    url: str
    token: str
    split: str = "script"
    link: LinkSpec | None = None
    lead: float | None = None  # s; None: from the round trip measured at connect
    diverge_mm: float = 10.0
    tick: float = 0.25  # the run's tick length, s
    log: TextIO | None = None
    progress: Progress | None = None
    predict: bool = True
    record: Path | None = None  # --record: the predicted and the reported robot, a .rrd file
    rerun: bool = False  # --rerun: the same, live in a spawned viewer
    quiet: bool = False  # --quiet: say nothing but errors
