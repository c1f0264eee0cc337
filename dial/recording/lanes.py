"""The event lanes of a recording, from the log records: the script's diagram as it happened.

Pure Python (no MuJoCo, no rerun). A :class:`~dial.parser.lanes.LanePlan` says which lanes
a script has and in what order, and which runs hold (``-``); :class:`Lanes` turns log
records, as they come, into :class:`Phase` changes of those lanes, which
:mod:`dial.recording.rerun_sink` sends as rerun ``StateChange``s.

- One lane per event, in script order (the line where the event first appears); a called
  script's events are grouped under the callee's name. The viewer sorts lanes by entity path,
  so a lane's path carries its place: ``01_to_bulb``, ``05_containment/02_touch``.
- A run is drawn from its start to its end and labelled with its outcome (``running`` until
  it ends); a one-tick run that takes no simulated time is drawn to the end of its tick.
  Its hold (``-``) follows, as ``held``, to the end of its last ``-`` tick.
- Markers, one tick wide: a condition test on the tested event's lane (``true``/``false``),
  a monitor that fired (``fired``). An event that also runs gets them on a lane of their
  own just below its runs (``05_grasp_bulb.tests``), so a marker never hides a run.
- A disturbance is drawn from its begin to its end on ``disturb/<what>``.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from dial.parser.lanes import Key, LanePlan

Lane = tuple[str, ...]  # entity path parts of a lane
LogRecord = Mapping[str, Any]  # a log record as read back (a JSON object)

RUNNING, HELD, FIRED, DISTURBED = "running", "held", "fired", "disturbed"
# state -> colour (RGB); outcomes follow DESIGN 2.5, the rest are this module's
STATE_COLORS: dict[str, tuple[int, int, int]] = {
    RUNNING: (66, 165, 245),
    "done": (67, 160, 71),
    "missed": (255, 167, 38),
    "timeout": (229, 57, 53),
    "error": (229, 57, 53),
    "preempted": (171, 71, 188),
    HELD: (110, 110, 110),
    "true": (38, 166, 154),
    "false": (141, 110, 99),
    FIRED: (236, 64, 122),
    DISTURBED: (255, 112, 67),
}
DEFAULT_TICK = 0.1  # s; the marker width until the run's first tick has ended
TESTS = ".tests"  # suffix of the lane that holds an event's markers when the event also runs


def lane_key(record: LogRecord) -> Key:
    """The lane of a record's ``event``: a called script's events carry that script's name."""
    script = record.get("script")
    return (Path(str(script)).stem, str(record["event"])) if script else (str(record["event"]),)


@dataclass(frozen=True)
class Phase:
    """A lane enters ``state`` at simulated time ``t`` (s) and ``tick``; None ends the phase."""

    lane: Lane
    state: str | None
    t: float
    tick: int


@dataclass
class _Run:
    key: Key
    t0: float
    k0: int
    line: int
    script: str


@dataclass
class _Ended:
    run: _Run
    outcome: str
    t1: float
    k1: int


class Lanes:
    """Turns log records, in log order, into the phases of the lanes."""

    def __init__(self, plan: LanePlan | None = None) -> None:
        self.plan = plan or LanePlan(())
        self._paths: dict[Key, Lane] = {}
        self._count: dict[Key, int] = {}  # lanes numbered so far, per group (() at the top)
        for key in self.plan.order:
            self.path(key)
        self._started: set[Key] = set()
        self._runs: dict[Key, _Run] = {}
        self._ended: list[_Ended] = []
        self._clear: dict[Lane, tuple[float, int]] = {}  # a lane's pending end of phase
        self._held: dict[Lane, int] = {}  # lane -> the last tick of its hold
        self._disturbed: dict[Lane, float] = {}  # disturbance lane -> when it began
        self._block: dict[int, int] = {}  # tick -> block tick
        self._tick: float | None = None  # the nominal tick length, once seen
        self._last = (0.0, 0)

    def path(self, key: Key) -> Lane:
        """The lane's entity path parts, numbered in order of first sight after the plan's."""
        if key not in self._paths:
            parent = self.path(key[:-1]) if len(key) > 1 else ()
            n = self._count[key[:-1]] = self._count.get(key[:-1], 0) + 1
            self._paths[key] = (*parent, f"{n:02d}_{_safe(key[-1])}")
        return self._paths[key]

    @property
    def width(self) -> float:
        """A marker's width in simulated time: one nominal tick."""
        return self._tick if self._tick is not None else DEFAULT_TICK

    def feed(self, record: LogRecord) -> list[Phase]:
        """The phases that ``record`` starts or ends now."""
        kind = record["kind"]
        if kind in ("start", "end", "condition", "monitor", "disturb", "tick"):
            t = float(record.get("t", record.get("t1", 0.0)))
            self._last = (t, int(record.get("tick", self._last[1])))
        handler = _HANDLERS.get(kind)
        return [] if handler is None else handler(self, record)

    def flush(self, until: float | None = None) -> list[Phase]:
        """Pending ends of phases up to simulated time ``until``; all of them when None
        (at the end of the run: runs whose tick never ended, and holds, end where it stopped)."""
        out: list[Phase] = []
        if until is None:
            for ended in self._ended:
                out += self._finish(ended, ended.t1)
            self._ended = []
            t, k = self._last
            for lane in self._held:
                self._clear[lane] = (t, k + 1)
            self._held = {}
        for lane, (t, k) in sorted(self._clear.items(), key=lambda item: item[1]):
            if until is None or t <= until:
                out.append(Phase(lane, None, t, k))
                del self._clear[lane]
        return out

    # -- the records ---------------------------------------------------------------------------
    def _start(self, r: LogRecord) -> list[Phase]:
        key = lane_key(r)
        self._started.add(key)
        t, k = float(r["t"]), int(r["tick"])
        self._runs[key] = _Run(key, t, k, int(r.get("line", 0)), str(r.get("script", "")))
        return self._begin(self.path(key), RUNNING, t, k)

    def _end(self, r: LogRecord) -> list[Phase]:
        run = self._runs.pop(lane_key(r), None)
        if run is not None:  # a condition-only event's instant run is drawn by its test
            self._ended.append(_Ended(run, str(r["outcome"]), float(r["t"]), int(r["tick"])))
        return []

    def _tick_end(self, r: LogRecord) -> list[Phase]:
        k, t1 = int(r["tick"]), float(r["t1"])
        self._block[k] = int(r.get("block_tick", 0))
        if self._tick is None and not r.get("stretch"):
            self._tick = t1 - float(r["t0"])
        out: list[Phase] = []
        for ended in [e for e in self._ended if e.k1 <= k]:
            out += self._finish(ended, t1)
            self._ended.remove(ended)
        for lane in [lane for lane, last in self._held.items() if last <= k]:
            self._clear[lane] = (t1, k + 1)
            del self._held[lane]
        return out

    def _condition(self, r: LogRecord) -> list[Phase]:
        text = str(r["condition"])
        key = lane_key({**r, "event": text.lstrip("!")})
        truth = bool(r["value"]) != text.startswith("!")
        return self._mark(key, "true" if truth else "false", float(r["t"]), int(r["tick"]))

    def _monitor(self, r: LogRecord) -> list[Phase]:
        t, k = float(r["t"]), int(r["tick"])
        for lane in self._held:  # the rest of the block is skipped: its holds end here
            self._clear[lane] = (t, k + 1)
        self._held = {}
        return self._mark(lane_key(r), FIRED, t, k)

    def _disturb(self, r: LogRecord) -> list[Phase]:
        lane = ("disturb", _safe(str(r["what"])))
        t, k = float(r["t"]), int(r["tick"])
        if r.get("phase") == "end":
            begun = self._disturbed.pop(lane, t)
            self._clear[lane] = (max(t, begun + self.width), k + 1)
            return []
        self._disturbed[lane] = t
        return self._begin(lane, DISTURBED, t, k)

    # -- phases --------------------------------------------------------------------------------
    def _begin(self, lane: Lane, state: str, t: float, k: int) -> list[Phase]:
        """``lane`` enters ``state``; its pending end is sent first if it comes before."""
        out = []
        pending = self._clear.pop(lane, None)
        if pending is not None and pending[0] <= t:
            out.append(Phase(lane, None, *pending))
        self._held.pop(lane, None)
        out.append(Phase(lane, state, t, k))
        return out

    def _mark(self, key: Key, state: str, t: float, k: int) -> list[Phase]:
        lane = self.path(key)
        if key in self._started and key not in self.plan.condition_only:
            lane = (*lane[:-1], lane[-1] + TESTS)
        out = self._begin(lane, state, t, k)
        self._clear[lane] = (t + self.width, k + 1)
        return out

    def _finish(self, ended: _Ended, tick_end: float) -> list[Phase]:
        """A run's outcome over its span, then its hold or the end of its phase."""
        run, lane = ended.run, self.path(ended.run.key)
        # A run that took no simulated time is drawn over its tick: a tick is its least span.
        end = next((t for t in (ended.t1, tick_end) if t > run.t0), run.t0 + self.width)
        out = [Phase(lane, ended.outcome, run.t0, run.k0)]
        hold = 0
        if ended.outcome in ("done", "missed"):
            hold = self.plan.holds.get((run.script, run.line, self._block.get(run.k0, 0)), 0)
        if hold:
            out.append(Phase(lane, HELD, end, ended.k1 + 1))
            self._held[lane] = ended.k1 + hold
        else:
            self._clear[lane] = (end, ended.k1 + 1)
        return out


def _safe(name: str) -> str:
    """A name usable as one entity path part without escapes."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)


_HANDLERS = {
    "start": Lanes._start,
    "end": Lanes._end,
    "tick": Lanes._tick_end,
    "condition": Lanes._condition,
    "monitor": Lanes._monitor,
    "disturb": Lanes._disturb,
}

__all__ = ["STATE_COLORS", "LanePlan", "Lanes", "Phase", "lane_key"]
