"""Coasting (dial/scheduler/periods.py): when every active run is open-loop, the tick loop
takes their courses at once and the robot coasts through the rest of the tick. It must give
exactly the periods, set-points and records of stepping them one by one.

On the fake robot a paced run (``run_fake`` keeps pace with trio's MockClock) never coasts,
and an unpaced one (as ``dial run`` runs) does: the two must agree record for record and
set-point for set-point, whatever happens inside a coast (a monitor firing, a safety fault,
an indeterminate run ending and leaving the rest of the tick to the open-loop runs).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np
import pytest

from dial.geometry import smooth, smooth_array
from dial.primitives.arm import Segment
from dial.scheduler import Outcome
from dial.testing import Behaviour, run_fake

from .test_reactions import DEFS

LANES = DEFS + (
    "arm   #=====\nidx   #---\nmid    #====\nback  #\n@repeat 2\narm  #==\nmid  #\n@end\n"
)
STRETCH = DEFS + "arm  #=====\ngrab  #=\nidx     #=\n"
WATCHED = DEFS + ("arm   #=====\nidx   #---\nslip  ~~~~~~\n@on slip\nback  #=\n@end\nmid  #==\n")

CASES: dict[str, tuple[str, dict[str, object]]] = {
    "lanes": (LANES, {}),
    "an indeterminate run ends mid-tick": (STRETCH, {"behaviours": {"grab": Behaviour(0.13)}}),
    "an indeterminate run stretches": (STRETCH, {"behaviours": {"grab": Behaviour(0.27)}}),
    "a monitor fires mid-coast": (WATCHED, {"holds": {"slip": {23}}}),
    "a monitor fires in a span's first period": (WATCHED, {"holds": {"slip": {1}}}),
    "a safety fault mid-coast": (LANES, {"fault_at": {37: "joint 2 at its limit"}}),
}


def _run(text: str, paced: bool, options: Mapping[str, object], lag: float = 0.0) -> object:
    behaviours = options.get("behaviours")
    holds = options.get("holds")
    fault_at = options.get("fault_at")
    return run_fake(
        text,
        tick=0.1,
        paced=paced,
        behaviours=behaviours,  # type: ignore[arg-type]
        holds=holds,  # type: ignore[arg-type]
        fault_at=fault_at,  # type: ignore[arg-type]
        lag=lag,
    )


@pytest.mark.parametrize("case", list(CASES))
def test_coasting_gives_the_periods_records_and_set_points_of_stepping(case: str) -> None:
    text, options = CASES[case]
    stepped = _run(text, paced=True, options=options)
    coasted = _run(text, paced=False, options=options)
    assert stepped.robot.coasts == []  # type: ignore[attr-defined]
    assert coasted.robot.coasts != []  # type: ignore[attr-defined]
    assert coasted.log.records == stepped.log.records  # type: ignore[attr-defined]
    assert coasted.robot.trace == stepped.robot.trace  # type: ignore[attr-defined]
    assert coasted.robot.holds_at == stepped.robot.holds_at  # type: ignore[attr-defined]
    assert coasted.robot.stops == stepped.robot.stops  # type: ignore[attr-defined]
    same, done = (replace(r.summary, error=str(r.summary.error)) for r in (stepped, coasted))  # type: ignore[attr-defined]
    assert done == same


@pytest.mark.parametrize("case", list(CASES))
def test_a_paced_run_behind_the_clock_coasts_through_the_periods_already_due(case: str) -> None:
    """A robot that takes three periods' time to simulate one (a loaded machine) falls
    behind a paced run's clock: it coasts through the periods whose time has passed, never
    ahead of the clock, and gives what stepping gives."""
    text, options = CASES[case]
    stepped = _run(text, paced=True, options=options)
    behind = _run(text, paced=True, options=options, lag=0.03)
    assert behind.robot.coasts != []  # type: ignore[attr-defined]
    assert behind.log.records == stepped.log.records  # type: ignore[attr-defined]
    assert behind.robot.trace == stepped.robot.trace  # type: ignore[attr-defined]
    assert behind.robot.holds_at == stepped.robot.holds_at  # type: ignore[attr-defined]
    assert behind.robot.stops == stepped.robot.stops  # type: ignore[attr-defined]
    assert behind.trio_time > 2 * stepped.trio_time  # type: ignore[attr-defined]
    on_time = _run(text, paced=True, options=options, lag=0.005)  # faster than the clock
    assert on_time.robot.coasts == []  # type: ignore[attr-defined]
    assert on_time.log.records == stepped.log.records  # type: ignore[attr-defined]


def test_a_coast_stops_at_the_period_a_monitor_fires() -> None:
    result = _run(WATCHED, paced=False, options={"holds": {"slip": {23}}})
    (monitor,) = result.log.of("monitor")  # type: ignore[attr-defined]
    assert monitor["period"] == 23
    ended = [r for r in result.log.of("end") if r["outcome"] == Outcome.PREEMPTED.value]  # type: ignore[attr-defined]
    assert [r["event"] for r in ended] == ["arm"]
    assert result.robot.holds_at == [(23, frozenset({"arm"}))]  # type: ignore[attr-defined]


def test_no_coast_while_a_closed_loop_run_is_active() -> None:
    result = _run(STRETCH, paced=False, options={"behaviours": {"grab": Behaviour(0.27)}})
    # grab runs (closed-loop) through ticks 2 and 3 and stretches tick 3 by 7 periods: the
    # only coasts are tick 1 (arm alone) and the ticks after grab ended.
    coasts = [first for first, _ in result.robot.coasts]  # type: ignore[attr-defined]
    assert coasts[0] == 1
    assert not any(11 <= p <= 37 for p in coasts)


def test_a_coast_runs_on_through_quiet_tick_boundaries_and_records_each_tick() -> None:
    # arm runs ticks 1-6 alone after idx's one tick: from tick 2 on no run starts or ends
    # before tick 6's end, so one coast takes ticks 2 to 6 (50 periods).
    result = _run(DEFS + "arm  #=====\nidx  #\n", paced=False, options={})
    assert (11, 50) in result.robot.coasts  # type: ignore[attr-defined]
    ticks = [(r["tick"], r["t0"], r["t1"]) for r in result.log.of("tick")]  # type: ignore[attr-defined]
    assert ticks == [(k, (k - 1) / 10, k / 10) for k in range(1, 7)]


def test_smooth_array_is_smooth_bit_for_bit() -> None:
    u = np.concatenate([np.linspace(-0.1, 1.1, 1201), np.random.default_rng(7).random(1000)])
    assert smooth_array(u).tolist() == [smooth(float(x)) for x in u]


def test_a_segments_at_array_is_its_at_bit_for_bit() -> None:
    rng = np.random.default_rng(3)
    for rows in (2, 3, 17):
        segment = Segment(rng.normal(size=(rows, 6)), 1.0)
        u = np.concatenate([[0.0, 1.0, 1.5, -0.2], rng.random(200)])
        expected = np.array([segment.at(float(x)) for x in u])
        assert np.array_equal(segment.at_array(u), expected)
