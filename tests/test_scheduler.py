"""Scheduler semantics on the fake robot and virtual time: exact ticks and times."""

from __future__ import annotations

import signal
from pathlib import Path
from typing import Any

import pytest
import trio
import trio.testing

from dial.parser import check_text, expand, load
from dial.scheduler import Outcome
from dial.scheduler.log import EventLog
from dial.scheduler.primitive import Ended, Now, Primitive
from dial.scheduler.runner import Runner
from dial.scheduler.signals import catch_stop_signals
from dial.scheduler.types import RunInfo
from dial.testing import Behaviour, FakeFactory, FakeRobot, run_fake

from .conftest import ROOT

ARM = '% arm puma_command "moves above"\n'
HAND = '% pose hand_pose "open_hand"\n'
GRAB = '% grab grasp_force "0x0666_0x0222 4N" timeout=2s\n'


def test_lightbulb_timeline_runs_at_the_compiled_ticks() -> None:
    script = load(ROOT / "scripts" / "lightbulb.dial")
    # Each grasp takes 0.6 s against a 0.25 s tick: its tick stretches by 35 periods. Each
    # wait for the thumb to rest runs once; the first tug holds (threaded), the second comes
    # free, so the unscrewing loop runs twice and its @if once. No monitor fires.
    D, M = Outcome.DONE, Outcome.MISSED
    behaviours = {
        "grasp_bulb": Behaviour(duration=0.6),
        "ringing": Behaviour(outcomes=(D, M) * 3),
        "tug": Behaviour(outcomes=(D, M)),
    }
    result = run_fake(script, tick=0.25, behaviours=behaviours)
    assert result.summary.ok
    runs = {(p.run.event, p.run.line): p.run for p in expand(script).runs}
    block_tick, seen = 0, []
    for r in result.log.records:  # every run starts and ends at its tick within its block
        if r["kind"] == "block":
            block_tick = r["tick"]
        elif r["kind"] == "start":
            seen.append(r["event"])
            assert r["tick"] - block_tick + 1 == runs[(r["event"], r["line"])].start, r
        elif r["kind"] == "end" and r["event"] not in script.condition_only:
            assert r["tick"] - block_tick + 1 == runs[(r["event"], r["line"])].exec_end, r
    assert seen.count("grasp_bulb") == seen.count("tug") == 2 and seen.count("ungrasp") == 1
    assert "back_off" not in seen and seen[-1] == "retract_arm"
    grasp_ticks = [r["tick"] for r in result.log.of("start") if r["event"] == "grasp_bulb"]
    assert result.stretches() == dict.fromkeys(grasp_ticks, 35)
    ticks = result.summary.ticks
    assert result.summary.sim_time == pytest.approx(ticks * 0.25 + len(grasp_ticks) * 0.35)
    assert result.trio_time == pytest.approx(result.summary.sim_time)


def test_one_tick_grasp_stretches_while_the_arm_holds_its_tick_end_set_point() -> None:
    text = ARM + GRAB + "arm  #====\ngrab   #\n"
    result = run_fake(text, tick=0.25, behaviours={"grab": Behaviour(duration=0.6)})
    assert result.starts("grab") == [(3, 0.5)]
    assert result.ends("grab") == [(3, 1.1, "done")]
    assert result.stretches() == {3: 35}
    assert result.ends("arm") == [(5, 1.6, "done")]
    arm = [c["arm"] for c in result.robot.trace]
    # Tick time: 3 of the arm's 5 ticks are done when tick 3's nominal time ends...
    assert arm[74] == pytest.approx(0.6)
    # ...and the set-point stands still for the whole stretch (periods 75-109)...
    assert arm[75:110] == [pytest.approx(0.6)] * 35
    # ...then resumes, one period of tick time at a time, to the goal.
    assert arm[110] == pytest.approx(0.6 + 1 / 125)
    assert arm[-1] == pytest.approx(1.0)
    assert len(arm) == 160


def test_trajectory_vs_goto_with_dwell_vs_goto() -> None:
    text = (
        '% traj hand_pose "open_hand" fingers=0x000F\n'
        '% dwell hand_pose "open_hand" fingers=0x00F0\n'
        '% goto hand_pose "open_hand" fingers=0x0F00\n'
        "traj  #===\ndwell #---\ngoto  #\n"
    )
    result = run_fake(text, tick=0.1)
    trace = result.robot.trace
    assert [round(c["index"], 3) for c in trace[9::10]] == [0.25, 0.5, 0.75, 1.0]
    assert trace[0]["index"] == pytest.approx(0.025)  # interpolated from the first period
    assert trace[0]["middle"] == 1.0 and trace[0]["ring"] == 1.0  # jumps at once
    assert result.ends("traj") == [(4, pytest.approx(0.4), "done")]
    assert result.ends("dwell") == [(1, pytest.approx(0.1), "done")]  # then held through tick 4
    assert result.ends("goto") == [(1, pytest.approx(0.1), "done")]
    assert result.summary.ticks == 4  # the dwell keeps the block going


def test_indeterminate_run_that_ends_early_does_not_shorten_its_tick() -> None:
    result = run_fake(GRAB + "grab #\n", tick=0.25, behaviours={"grab": Behaviour(duration=0.1)})
    assert result.ends("grab") == [(1, pytest.approx(0.1), "done")]
    assert result.stretches() == {}
    assert result.summary.sim_time == pytest.approx(0.25)


def test_multi_tick_indeterminate_run_stretches_only_its_last_tick() -> None:
    result = run_fake(GRAB + "grab #==\n", tick=0.1, behaviours={"grab": Behaviour(duration=0.45)})
    assert result.stretches() == {3: 15}
    assert result.ends("grab") == [(3, pytest.approx(0.45), "done")]


def test_missed_is_not_an_error() -> None:
    text = GRAB + HAND + "grab #\npose  #\n"
    result = run_fake(text, behaviours={"grab": Behaviour(outcomes=[Outcome.MISSED])})
    assert result.summary.ok
    assert result.ends("grab") == [(1, pytest.approx(0.01), "missed")]  # first period
    assert result.starts("pose") == [(2, pytest.approx(0.1))]


@pytest.mark.parametrize(
    ("behaviour", "outcome", "when"),
    [
        (Behaviour(duration=None), "timeout", 2.0),
        (Behaviour(duration=0.3, outcomes=[Outcome.ERROR], message="tendon slipped"), "error", 0.3),
    ],
)
def test_timeout_and_error_abort_the_script(
    behaviour: Behaviour, outcome: str, when: float
) -> None:
    text = ARM + GRAB + "arm  #=\ngrab   #\narm     #\n"
    result = run_fake(text, tick=0.1, behaviours={"grab": behaviour})
    summary = result.summary
    assert not summary.ok and summary.error is not None
    assert result.ends("grab") == [(3, pytest.approx(0.2 + when), outcome)]
    message = str(summary.error)
    assert "event 'grab' (defined on line 2 of fake.dial)" in message
    assert f"ended {outcome} at tick 3" in message
    assert summary.error.event == "grab" and summary.error.tick == 3
    assert result.starts("arm") == [(1, 0.0)]  # the later arm run never started
    assert result.robot.held  # every effector holds its pose
    assert result.log.of("error")[0]["tick"] == 3


def test_safety_monitor_fault_aborts_within_one_period() -> None:
    result = run_fake(ARM + "arm #====\n", tick=0.1, fault_at={7: "joint 2 at its limit"})
    assert not result.summary.ok
    assert "safety monitor: joint 2 at its limit (running: arm)" in str(result.summary.error)
    assert result.summary.periods == 7
    assert result.robot.held


def test_repeat_until_stops_when_the_condition_holds() -> None:
    text = ARM + "% touch tactile_contact finger=index\n@repeat until touch max 5\narm #\n@end\n"
    outcomes = [Outcome.MISSED, Outcome.MISSED, Outcome.DONE]
    result = run_fake(text, behaviours={"touch": Behaviour(outcomes=outcomes)})
    assert result.summary.ok
    assert [t for t, _ in result.starts("arm")] == [1, 2, 3]
    assert [r["value"] for r in result.log.of("condition")] == [False, False, True]


def test_repeat_until_reaching_max_is_an_error() -> None:
    text = ARM + "% touch tactile_contact finger=index\n@repeat until touch max 4\narm #\n@end\n"
    result = run_fake(text, behaviours={"touch": Behaviour(outcomes=[Outcome.MISSED])})
    assert not result.summary.ok
    assert "'@repeat until touch' on line 3 of fake.dial reached its max of 4" in str(
        result.summary.error
    )
    assert len(result.starts("arm")) == 4


def test_repeat_while_tests_first_and_max_is_an_error() -> None:
    text = ARM + "% touch tactile_contact finger=index\n@repeat while touch max 3\narm #\n@end\n"
    never = run_fake(text, behaviours={"touch": Behaviour(outcomes=[Outcome.MISSED])})
    assert never.summary.ok and never.starts("arm") == []
    twice = [Outcome.DONE, Outcome.DONE, Outcome.MISSED]
    result = run_fake(text, behaviours={"touch": Behaviour(outcomes=twice)})
    assert result.summary.ok and len(result.starts("arm")) == 2
    forever = run_fake(text, behaviours={"touch": Behaviour(outcomes=[Outcome.DONE])})
    assert not forever.summary.ok and len(forever.starts("arm")) == 3
    assert "reached its max of 3" in str(forever.summary.error)


def test_repeat_count_and_condition_on_a_run_event() -> None:
    text = ARM + GRAB + "@repeat 3\narm #\n@end\ngrab #\n@if grab\narm #\n@else\ngrab #\n@end\n"
    result = run_fake(text, behaviours={"grab": Behaviour(outcomes=[Outcome.MISSED, Outcome.DONE])})
    assert [t for t, _ in result.starts("arm")] == [1, 2, 3]
    # grab ended missed, so '@if grab' is false and the else branch runs grab again.
    assert [t for t, _ in result.starts("grab")] == [4, 5]
    assert result.log.of("condition")[0]["value"] is False


@pytest.mark.parametrize(("first", "branch"), [(Outcome.DONE, "arm"), (Outcome.MISSED, "pose")])
def test_if_else_branches_on_a_sensed_outcome(first: Outcome, branch: str) -> None:
    touch = "% touch tactile_contact finger=index\n"
    text = ARM + HAND + touch + "@if touch\narm #\n@else\npose #\n@end\n"
    result = run_fake(text, behaviours={"touch": Behaviour(outcomes=[first])})
    assert [r["event"] for r in result.log.of("start")] == [branch]


def test_call_runs_the_callee_with_its_own_events(tmp_path: Path) -> None:
    sub = tmp_path / "sub.dial"
    sub.write_text('% arm hand_pose "point"\n% j get_joints\narm #=\n@if j\narm #\n@end\n')
    main = tmp_path / "main.dial"
    main.write_text(ARM + "arm #\n@call sub.dial\narm #\n")
    script = check_text(main.read_text(), str(main))
    assert script is not None
    result = run_fake(script)
    # Every record of the callee's events says whose they are: the names repeat.
    callee = str(tmp_path / "sub.dial")
    runs = [
        (r["kind"], r["event"], r["tick"], r.get("script"))
        for r in result.log.records
        if r["kind"] in ("start", "end")
    ]
    assert runs == [
        ("start", "arm", 1, None),
        ("end", "arm", 1, None),
        ("start", "arm", 2, callee),
        ("end", "arm", 3, callee),
        ("end", "j", 3, callee),  # the condition-only sensing event, run by the @if
        ("start", "arm", 4, callee),
        ("end", "arm", 4, callee),
        ("start", "arm", 5, None),
        ("end", "arm", 5, None),
    ]
    (condition,) = result.log.of("condition")
    assert condition["condition"] == "j" and condition["script"] == callee
    # The callee's 'arm' is a hand pose: it moved the fingers, not the arm.
    assert result.robot.trace[19]["index"] == pytest.approx(0.5)
    assert result.robot.trace[19]["arm"] == 1.0


def test_sensing_runs_take_no_time() -> None:
    text = ARM + "% j get_joints\narm #\nj    #\n"
    result = run_fake(text, tick=0.1)
    assert result.ends("j") == [(2, pytest.approx(0.1), "done")]
    assert result.summary.sim_time == pytest.approx(0.2)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_log_does_not_depend_on_trio_task_order(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    import trio._core._run as trio_run  # private: the only way to pick trio's task order

    script = load(ROOT / "scripts" / "lightbulb.dial")
    behaviours = {"grasp_bulb": Behaviour(duration=0.37)}
    reference = run_fake(script, tick=0.05, behaviours=behaviours).log.records
    monkeypatch.setattr(trio_run, "_ALLOW_DETERMINISTIC_SCHEDULING", True)
    trio_run._r.seed(seed)  # shuffles every batch of ready tasks differently per seed
    shuffled = run_fake(script, tick=0.05, behaviours=behaviours).log.records
    assert shuffled == reference


class _CtrlC(Primitive):
    """A run whose start is hit by Ctrl-C, as during a long native computation (an IK solve)."""

    def start(self, snapshot: Any) -> None:
        try:
            signal.raise_signal(signal.SIGINT)  # the handler runs now, in this synchronous code
        except KeyboardInterrupt:  # as native code may: daqp's solve turned it into this
            raise ValueError(
                "Buffer dtype mismatch, expected 'int' but got Python object"
            ) from None

    def step(self, snapshot: Any, now: Now) -> Ended | None:
        return None


@pytest.mark.parametrize("tick", [1, 3])  # also in the very first tick, before any period
def test_ctrl_c_stops_the_run_at_a_checkpoint_with_the_arm_held(tick: int) -> None:
    # Ctrl-C during a native computation must not surface as whatever error that code makes
    # of a KeyboardInterrupt: the run ends as an interrupt (exit 130), logged, arm held.
    lane = " " * (tick - 1) + "#"
    text = ARM + HAND + f"arm  #====\npose {lane}\n"
    script = check_text(text, "x.dial")
    assert script is not None
    robot, log = FakeRobot(), EventLog()

    class Factory(FakeFactory):
        def primitive(self, info: RunInfo) -> Primitive:
            return _CtrlC() if info.event.name == "pose" else super().primitive(info)

    clock = trio.testing.MockClock(autojump_threshold=0)
    with catch_stop_signals() as stop:  # who starts a run owns the signals; the runner polls
        runner = Runner(robot, Factory(robot, {}), 0.1, log, stop=stop)
        summary = trio.run(runner.run, script, clock=clock)
    assert summary.interrupted == "SIGINT" and not summary.ok
    assert robot.held
    last = log.records[-1]
    assert last["kind"] == "interrupted" and last["tick"] == tick and last["signal"] == "SIGINT"
    start = (tick - 1) * 0.1
    assert start <= last["t"] <= start + 0.011  # at most a period after the signal
    assert not [r for r in log.records if r["kind"] == "end"]  # the arm's move never finished


def test_the_log_never_holds_nan_or_inf() -> None:
    """A non-finite number anywhere in a record is written as null: the log stays strict JSON
    (issue 15: --perturb nan wrote NaN)."""
    import io
    import json

    import numpy as np

    sink = io.StringIO()
    log = EventLog(sink)
    log.write("x", a=float("nan"), b=[1.0, float("inf")], c={"d": np.array([-np.inf, 2.5])})
    line = sink.getvalue()
    assert line == '{"kind":"x","a":null,"b":[1.0,null],"c":{"d":[null,2.5]}}\n'
    json.loads(line, parse_constant=lambda c: pytest.fail(f"{c} in the log"))
