"""``dial tune`` stopped by a signal: one Ctrl-C, two in quick succession (the second used to
catch the pool half shut down, and the exit then waited forever for a worker, with signals
ignored), or SIGTERM (which used to kill the sweep alone and orphan its workers). Each ends
with its exit status and one line, and leaves no process behind."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

SWEEP = ["tune", "pour.dial", "--ticks", "0.2:0.3:2", "--trials", "50", "--jobs", "2"]


def _session(sid: int) -> list[int]:
    """The live processes of session ``sid`` (read from /proc: no procps needed)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue  # it ended while we looked
        if int(fields[3]) == sid and fields[0] != "Z":
            found.append(int(entry.name))
    return found


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize(
    ("signals", "status", "message"),
    [
        ((signal.SIGINT,), 130, "dial: interrupted"),
        ((signal.SIGINT, signal.SIGINT), 130, "dial: interrupted"),  # 50 ms apart
        ((signal.SIGTERM,), 143, "dial: terminated"),
    ],
)
def test_a_signal_stops_the_sweep_and_its_workers(
    signals: tuple[int, ...], status: int, message: str
) -> None:
    proc = subprocess.Popen(
        [sys.executable, "-m", "dial.cli", *SWEEP],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,  # its own process group: the signals reach it and its workers
    )
    try:
        deadline = time.monotonic() + 120
        while len(_session(proc.pid)) < 4 and time.monotonic() < deadline:
            time.sleep(0.1)  # the sweep, its resource tracker and two workers
        assert proc.poll() is None, "the sweep ended before the signal"
        time.sleep(2.0)  # the workers are in their first trials
        for k, sig in enumerate(signals):
            if k:
                time.sleep(0.05)
            os.killpg(proc.pid, sig)
        assert proc.wait(timeout=60) == status
        assert proc.stderr is not None
        assert proc.stderr.read().decode().splitlines()[-1] == message
        deadline = time.monotonic() + 20
        while _session(proc.pid) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert _session(proc.pid) == []  # no worker outlives the sweep
    finally:
        if _session(proc.pid):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
