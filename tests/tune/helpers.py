"""A synthetic script and fake-robot backends for the tune tests.

The backends are module-level functions so that worker processes can unpickle them.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from dial.testing.limited import limited_backend
from dial.tune import Trial, TrialRun

# One trajectory move over four ticks of the index finger. On the limited fake robot
# (1 unit/s, tolerance 0.02) it reaches min(1, 4 T): the shortest tick that gets within
# 0.02 of the goal is T = 0.245 s.
GO = '% go hand_pose "open_hand" fingers=0x000F\n\ngo #===\n'
BAD_TICK = 0.3  # where the failing backends fail


def write_go(directory: Path) -> Path:
    path = directory / "go.dial"
    path.write_text(GO, encoding="utf-8")
    return path


def raising(trial: Trial) -> TrialRun:
    if trial.tick == BAD_TICK:
        raise RuntimeError(f"boom at {trial.tick:g} s")
    return limited_backend(trial)


def diverging(trial: Trial) -> TrialRun:
    """The robot's safety monitor trips at the 5th control period, as on a diverged state."""
    fault = {5: "non-finite physics state"} if trial.tick == BAD_TICK else None
    return limited_backend(trial, fault_at=fault)


def dying(trial: Trial) -> TrialRun:
    """The worker process dies without a word, as on a crash in native code."""
    if trial.tick == BAD_TICK:
        os._exit(3)
    return limited_backend(trial)


def dies_once(trial: Trial) -> TrialRun:
    """The worker dies the first time it runs the trial at BAD_TICK, and only then.

    A marker file beside the script remembers the death across worker processes.
    """
    marker = Path(trial.script).with_suffix(f".died-{trial.trial}")
    if trial.tick == BAD_TICK and not marker.exists():
        marker.touch()
        os._exit(3)
    return limited_backend(trial)


def slow(trial: Trial) -> TrialRun:
    """Marks its start beside the script, then takes a second: for interrupting a sweep."""
    Path(trial.script).with_suffix(f".started-{trial.tick:g}").touch()
    time.sleep(1.0)
    return limited_backend(trial)
