"""Sweeps on the rate-limited fake robot: the threshold, failed trials, executors."""

from __future__ import annotations

import json as jsonlib
import sys
from io import StringIO
from pathlib import Path

import pytest

from dial.parser.check import load
from dial.testing.limited import limited_backend, run_limited
from dial.tune import (
    Backend,
    ProcessExecutor,
    SerialExecutor,
    TuneOptions,
    failed_trial,
    fastest_reliable,
    parse_ticks,
    plan,
    summarise,
    sweep,
    tune,
)
from dial.tune.executor import WORKER_DIED

from ..conftest import NEEDS_PLOT
from . import helpers

GRID = parse_ticks("0.05:0.5:10")


def test_limited_robot_ends_short_of_a_goal_commanded_too_fast(tmp_path: Path) -> None:
    script = load(helpers.write_go(tmp_path))
    slow, fast = run_limited(script, 0.25), run_limited(script, 0.2)
    assert slow.robot.positions["index"] == pytest.approx(1.0)
    assert slow.reached_goal
    assert fast.robot.positions["index"] == pytest.approx(0.8)  # 4 ticks x 0.2 s x 1 unit/s
    assert not fast.reached_goal
    assert fast.summary.ok  # the run itself completes: only the criterion fails


def test_threshold_is_the_shortest_tick_at_which_the_motion_is_feasible(tmp_path: Path) -> None:
    trials = plan(str(helpers.write_go(tmp_path)), "go.dial", GRID, trials=2)
    done: list[int] = []
    rows = summarise(sweep(trials, SerialExecutor(), limited_backend, done.append))
    assert done == list(range(1, 21))
    # 4 T >= 0.98 needs T >= 0.245 s: 0.05-0.2 fail, 0.25 and longer pass.
    assert [r.successes for r in rows] == [0, 0, 0, 0, 2, 2, 2, 2, 2, 2]
    assert [r.failed for r in rows[:4]] == [{"reached_goal": 2}] * 4
    assert all(r.failed == {} and r.errors == {} for r in rows[4:])
    best = fastest_reliable(rows)
    assert best is not None and best.tick == 0.25
    assert [r.median_time for r in rows[4:]] == pytest.approx([4 * r.tick for r in rows[4:]])
    assert rows[0].median_time is None  # task times are of successful trials only


@pytest.mark.parametrize(
    ("backend", "reason"),
    [
        (helpers.raising, "RuntimeError: boom at 0.3 s"),
        (helpers.diverging, "safety monitor: non-finite physics state (running: go)"),
    ],
)
def test_a_trial_that_raises_or_diverges_fails_alone_with_its_reason(
    tmp_path: Path, backend: Backend, reason: str
) -> None:
    trials = plan(str(helpers.write_go(tmp_path)), "go.dial", GRID, trials=2)
    rows = summarise(sweep(trials, SerialExecutor(), backend))
    bad = next(r for r in rows if r.tick == helpers.BAD_TICK)
    assert bad.successes == 0
    [(message, count)] = bad.errors.items()
    assert reason in message and count == 2
    assert [r.successes for r in rows if r.tick != helpers.BAD_TICK] == [0] * 4 + [2] * 5
    best = fastest_reliable(rows)
    assert best is not None and best.tick == 0.25


@pytest.mark.parametrize("preload", [(), ("dial.testing.limited",)])
def test_process_pool_gives_the_serial_results_and_survives_a_dead_worker(
    tmp_path: Path, in_root: Path, preload: tuple[str, ...]
) -> None:
    # With preload, a fork server forks the workers (it finds tests/ from the root).
    pool = ProcessExecutor(2, preload=preload)
    assert pool.method == ("forkserver" if preload else "spawn")
    trials = plan(str(helpers.write_go(tmp_path)), "go.dial", parse_ticks("0.2:0.35:4"), 1)
    serial = sweep(trials, SerialExecutor(), limited_backend)
    assert sweep(trials, pool, limited_backend) == serial
    done: list[int] = []
    dead = sweep(trials, pool, helpers.dying, done.append)
    assert done[-1] == 4
    assert [r.tick for r in dead] == [0.2, 0.25, 0.3, 0.35]
    assert [r.ok for r in dead] == [False, True, False, True]
    assert dead[2] == failed_trial(trials[2], WORKER_DIED)
    assert [dead[i] for i in (0, 1, 3)] == [serial[i] for i in (0, 1, 3)]


def _tune(
    tmp_path: Path, ticks: str, trials: int = 1, json: bool = False, plot: Path | None = None
) -> tuple[int, str, str]:
    out, err = StringIO(), StringIO()
    script = str(helpers.write_go(tmp_path))
    options = TuneOptions(script, parse_ticks(ticks), trials, json=json, plot=plot)
    status = tune(options, SerialExecutor(), limited_backend, out, err)
    return status, out.getvalue(), err.getvalue()


def test_tune_names_the_threshold_and_prints_the_table_as_json(tmp_path: Path) -> None:
    status, out, _ = _tune(tmp_path, "0.05:0.5:10", trials=2, json=True)
    assert status == 0
    assert "fastest reliable tick: 0.25 s (2/2 trials succeeded, median task time 1.00 s)" in out
    table = jsonlib.loads(out.splitlines()[-1])
    assert table["fastest_reliable_tick"] == 0.25
    assert [t["tick"] for t in table["ticks"]] == list(GRID)
    first = table["ticks"][0]
    assert first["success_rate"] == 0 and first["failed_criteria"] == {"reached_goal": 2}
    assert {k for k in first} >= {"trials", "successes", "median_time", "worst_time", "errors"}
    assert table["ticks"][4]["median_time"] == 1.0 and len(table["ticks"][4]["runs"]) == 2


def test_tune_says_when_no_tick_length_always_succeeds(tmp_path: Path) -> None:
    status, out, _ = _tune(tmp_path, "0.05:0.2:4")
    assert status == 1
    assert "no tick length reached 100 % success (no trial succeeded)" in out


def test_tune_plot_without_matplotlib_prints_the_table_and_exits_1(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "dial.tune.plot", None)  # import fails
    status, out, err = _tune(tmp_path, "0.25:0.3:2", plot=tmp_path / "p.png")
    assert status == 1
    assert "fastest reliable tick: 0.25 s" in out
    assert "--plot needs matplotlib: pip install 'dial[plot]'" in err
    assert not (tmp_path / "p.png").exists()


@NEEDS_PLOT  # without matplotlib, that is said instead
def test_tune_plot_that_cannot_be_written_is_reported_after_the_table(tmp_path: Path) -> None:
    status, out, err = _tune(tmp_path, "0.25:0.3:2", plot=tmp_path / "no" / "p.png")
    assert status == 1
    assert "fastest reliable tick: 0.25 s" in out
    assert f"dial: --plot {tmp_path / 'no' / 'p.png'}: [Errno 2] No such file" in err


def test_ticks_that_are_not_whole_control_periods_are_noted(tmp_path: Path) -> None:
    _, out, _ = _tune(tmp_path, "0.25:0.255:2")
    assert "note: ticks are whole control periods: 0.255 s ran as 0.26 s" in out
