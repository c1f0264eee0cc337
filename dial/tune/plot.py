"""The sweep as a figure: success rate and task time against tick length.

matplotlib is an optional extra (``pip install 'dial[plot]'``); importing this
module without it raises ImportError, which the command turns into a message.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

# The object API, not pyplot: no global figure state and no GUI backend to choose.
from matplotlib.figure import Figure

from dial.tune.report import TickRow, fastest_reliable


def plot(rows: Sequence[TickRow], path: Path, title: str) -> None:
    """Two panels over a shared tick axis: success rate (%), and median and worst task time."""
    ticks = [r.tick for r in rows]
    fig = Figure(figsize=(7, 6), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True)
    top.plot(ticks, [100 * r.success_rate for r in rows], "o-", color="tab:blue")
    top.set_ylabel("success rate (%)")
    top.set_ylim(-5, 105)
    top.set_title(title, fontsize="medium")
    # Task times exist only where some trial succeeded: gaps (NaN) elsewhere.
    median = [float("nan") if r.median_time is None else r.median_time for r in rows]
    worst = [float("nan") if r.worst_time is None else r.worst_time for r in rows]
    bottom.plot(ticks, median, "o-", color="tab:orange", label="median")
    bottom.plot(ticks, worst, "v--", color="tab:red", label="worst")
    bottom.set_ylabel("task time (simulated s)")
    bottom.set_xlabel("tick length (s)")
    bottom.legend(loc="upper left")
    best = fastest_reliable(rows)
    if best is not None:
        for ax in (top, bottom):
            ax.axvline(best.tick, color="tab:green", linestyle=":")
        top.annotate(
            f"fastest reliable: {best.tick:g} s",
            (best.tick, 50),
            xytext=(6, 0),
            textcoords="offset points",
            color="tab:green",
        )
    for ax in (top, bottom):
        ax.grid(True, alpha=0.3)
    fig.savefig(path, dpi=100)
