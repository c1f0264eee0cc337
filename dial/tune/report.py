"""A sweep's results per tick length: the table, the verdict and the JSON object.

Everything here is a pure function of the trial results, so the same sweep
prints the same text.
"""

from __future__ import annotations

import io
import statistics
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from rich import box
from rich.console import Console
from rich.table import Table

from dial.tune.trial import TrialResult


@dataclass(frozen=True)
class TickRow:
    """The trials at one tick length. Task times are of the successful trials only."""

    tick: float  # s, as asked for
    tick_length: float | None  # s, as run (whole control periods); None if every trial raised
    trials: int
    successes: int
    median_time: float | None  # simulated s
    worst_time: float | None
    failed: dict[str, int]  # criterion -> trials in which it did not hold
    errors: dict[str, int]  # reason -> trials that aborted or raised with it
    results: tuple[TrialResult, ...]

    @property
    def success_rate(self) -> float:
        return self.successes / self.trials


def summarise(results: Sequence[TrialResult]) -> list[TickRow]:
    """One row per tick length, shortest first."""
    by_tick: dict[float, list[TrialResult]] = {}
    for r in results:
        by_tick.setdefault(r.tick, []).append(r)
    rows = []
    for tick in sorted(by_tick):
        runs = by_tick[tick]
        times = [r.sim_time for r in runs if r.ok and r.sim_time is not None]
        lengths = [r.tick_length for r in runs if r.tick_length is not None]
        rows.append(
            TickRow(
                tick=tick,
                tick_length=lengths[0] if lengths else None,
                trials=len(runs),
                successes=sum(r.ok for r in runs),
                median_time=statistics.median(times) if times else None,
                worst_time=max(times) if times else None,
                failed=dict(sorted(Counter(c for r in runs for c in r.failed).items())),
                errors=dict(sorted(Counter(r.error for r in runs if r.error).items())),
                results=tuple(runs),
            )
        )
    return rows


def fastest_reliable(rows: Sequence[TickRow]) -> TickRow | None:
    """The shortest tick length at which every trial succeeded."""
    return next((row for row in rows if row.successes == row.trials), None)


def _seconds(value: float | None) -> str:
    return "-" if value is None else f"{value:.2f}"


def _counts(counts: dict[str, int]) -> str:
    return "\n".join(f"{n}x {name}" for name, n in counts.items())


def render_table(rows: Sequence[TickRow], title: str, width: int = 120) -> str:
    """The table as text; errors wrap inside their column."""
    table = Table(title=title, box=box.SIMPLE_HEAD, title_justify="left", show_lines=False)
    for name in ("tick (s)", "ok", "success", "median (s)", "worst (s)"):
        table.add_column(name, justify="right", no_wrap=True)
    table.add_column("failed criteria")
    table.add_column("errors")
    for row in rows:
        table.add_row(
            f"{row.tick:g}",
            f"{row.successes}/{row.trials}",
            f"{100 * row.success_rate:.0f} %",
            _seconds(row.median_time),
            _seconds(row.worst_time),
            _counts(row.failed) or "-",
            _counts(row.errors) or "-",
        )
    out = io.StringIO()
    Console(file=out, width=width, color_system=None, highlight=False).print(table)
    return "".join(line.rstrip() + "\n" for line in out.getvalue().splitlines())


def verdict(rows: Sequence[TickRow]) -> list[str]:
    """The answer, and what the table alone would not make plain."""
    best = fastest_reliable(rows)
    if best is None:
        top = max(rows, key=lambda r: (r.success_rate, -r.tick))
        best_so_far = (
            f"best: {top.tick:g} s with {top.successes}/{top.trials}"
            if top.successes
            else "no trial succeeded"
        )
        lines = [f"no tick length reached 100 % success ({best_so_far})"]
    else:
        lines = [
            f"fastest reliable tick: {best.tick:g} s ({best.successes}/{best.trials} trials "
            f"succeeded, median task time {_seconds(best.median_time)} s)"
        ]
        flaky = [f"{r.tick:g}" for r in rows if r.tick > best.tick and r.successes < r.trials]
        if flaky:
            lines.append(f"note: longer ticks did not all succeed: {', '.join(flaky)} s")
    moved = [
        f"{r.tick:g} s ran as {r.tick_length:g} s"
        for r in rows
        if r.tick_length is not None and abs(r.tick_length - r.tick) > 1e-9
    ]
    if moved:
        lines.append(f"note: ticks are whole control periods: {', '.join(moved)}")
    return lines


def _time(value: float | None) -> float | None:
    return None if value is None else round(value, 6)


def to_json(rows: Sequence[TickRow], **meta: Any) -> dict[str, Any]:
    """The whole table, every trial and the answer, as one JSON-ready object."""
    best = fastest_reliable(rows)
    return {
        **meta,
        "ticks": [
            {
                "tick": row.tick,
                "tick_length": _time(row.tick_length),
                "trials": row.trials,
                "successes": row.successes,
                "success_rate": round(row.success_rate, 6),
                "median_time": _time(row.median_time),
                "worst_time": _time(row.worst_time),
                "failed_criteria": row.failed,
                "errors": row.errors,
                "runs": [
                    {
                        "trial": r.trial,
                        "seed": r.seed,
                        "ok": r.ok,
                        "sim_time": _time(r.sim_time),
                        "failed_criteria": list(r.failed),
                        "error": r.error,
                    }
                    for r in row.results
                ],
            }
            for row in rows
        ],
        "fastest_reliable_tick": None if best is None else best.tick,
    }
