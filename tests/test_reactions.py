"""Monitors and reactions (DESIGN 2.7) on the fake robot and virtual time: exact periods.

The fake robot's watched conditions hold in the control periods its ``holds`` lists
(1-based, as the runner counts them); with a 0.1 s tick a block tick has 10 periods, so
period 23 is the third period of absolute tick 3.
"""

from __future__ import annotations

import pytest

from dial.scheduler import Outcome
from dial.testing import Behaviour, run_fake

DEFS = (
    '% arm   puma_command "moves above"\n'
    '% idx   hand_pose "open_hand" fingers=0x000F\n'
    '% mid   hand_pose "open_hand" fingers=0x00F0\n'
    '% back  hand_pose "open_hand" fingers=0x0F00\n'
    '% grab  grasp_force "0x0666_0x0222 4N" timeout=2s\n'
    "% slip  tactile_contact finger=thumb\n"
    "% bump  force_contact finger=index\n"
)


def records(result: object, kind: str) -> list[dict[str, object]]:
    return result.log.of(kind)  # type: ignore[attr-defined, no-any-return]


def kinds(result: object) -> list[tuple[object, ...]]:
    """The run records in order: (kind, event, tick, t[, outcome])."""
    out: list[tuple[object, ...]] = []
    for r in result.log.records:  # type: ignore[attr-defined]
        if r["kind"] in ("start", "end"):
            out.append((r["kind"], r["event"], r["tick"], r["t"], r.get("outcome")))
        elif r["kind"] == "monitor":
            out.append(("monitor", r["event"], r["tick"], r["t"], r["period"]))
    return out


BASIC = DEFS + (
    "arm   #=====\n"
    "idx   #---\n"
    "mid    #====\n"
    "slip  ~~~~~~\n"
    "@on slip\n"
    "back  #=\n"
    "@end\n"
    "@if arm\nidx #\n@else\nmid #\n@end\n"
    "@if slip\nback #\n@end\n"
)


def test_a_monitor_fires_in_the_period_its_condition_holds_and_preempts_the_block() -> None:
    result = run_fake(BASIC, tick=0.1, holds={"slip": {23}})
    assert result.summary.ok
    (monitor,) = records(result, "monitor")
    assert monitor == {
        "kind": "monitor",
        "event": "slip",
        "condition": "slip",
        "line": 12,
        "tick": 3,
        "t": 0.23,
        "period": 23,
        "step": 23,
    }
    # Every unended run of the block ends preempted at that period; idx had ended at tick 1.
    assert result.ends("arm") == [(3, pytest.approx(0.23), "preempted")]
    assert result.ends("mid")[0] == (3, pytest.approx(0.23), "preempted")
    assert result.ends("idx")[0] == (1, pytest.approx(0.1), "done")
    # The preempted runs' effectors hold where they are, in that period.
    assert result.robot.holds_at == [(23, frozenset({"arm", "middle"}))]
    # The interrupted tick is recorded as ending then; the rest of the block is skipped.
    tick3 = next(r for r in records(result, "tick") if r["tick"] == 3)
    assert (tick3["t1"], tick3.get("preempted")) == (0.23, True)


def test_the_reaction_starts_in_the_next_period_and_ticks_keep_counting() -> None:
    result = run_fake(BASIC, tick=0.1, holds={"slip": {23}})
    # The reaction's tick 1 is absolute tick 4, from period 24 (t = 0.23 s).
    assert result.starts("back")[0] == (4, pytest.approx(0.23))
    assert result.ends("back")[0] == (5, pytest.approx(0.43), "done")
    ticks = [(r["tick"], r["block_tick"], r["t0"], r["t1"]) for r in records(result, "tick")]
    assert ticks[2:5] == [(3, 3, 0.2, 0.23), (4, 1, 0.23, 0.33), (5, 2, 0.33, 0.43)]


def test_conditions_after_a_preemption() -> None:
    result = run_fake(BASIC, tick=0.1, holds={"slip": {23}})
    values = {r["condition"]: r["value"] for r in records(result, "condition")}
    # 'preempted' is not 'done'; the watched event reads whether it held when it fired.
    assert values == {"arm": False, "slip": True}
    assert [r["event"] for r in records(result, "start")][-1] == "back"


def test_stop_runs_in_the_blocks_fixed_order() -> None:
    text = DEFS + "mid   #====\narm   #=====\nidx   #====\nslip  ~~~~~~\n@on slip\n@end\n"
    result = run_fake(text, tick=0.1, holds={"slip": {15}})
    assert result.robot.stops == ["mid", "arm", "idx"]  # start tick, then line
    assert [k[1] for k in kinds(result) if k[0] == "end"] == ["mid", "arm", "idx"]


def test_no_monitor_outside_its_watched_span() -> None:
    text = DEFS + "arm   #=====\nslip   ~~.\n@on slip\n@end\n"  # watched in block ticks 2-3
    quiet = run_fake(text, tick=0.1, holds={"slip": set(range(1, 11)) | set(range(31, 61))})
    assert quiet.summary.ok and records(quiet, "monitor") == []
    assert quiet.ends("arm") == [(6, pytest.approx(0.6), "done")]
    fires = run_fake(text, tick=0.1, holds={"slip": {11}})  # the span's first period
    assert records(fires, "monitor")[0]["period"] == 11
    assert fires.robot.watched == [(11, "slip", False)]


def test_a_condition_that_holds_already_fires_in_the_first_period_of_the_span() -> None:
    text = DEFS + "arm   #=====\nslip  ~~~~~~\n@on !slip\n@end\narm   #\n"
    result = run_fake(text, tick=0.1)  # slip never holds: '!slip' holds from the start
    (monitor,) = records(result, "monitor")
    assert (monitor["condition"], monitor["period"], monitor["tick"]) == ("!slip", 1, 1)
    assert result.ends("arm")[0] == (1, pytest.approx(0.01), "preempted")
    assert result.starts("arm")[1] == (2, pytest.approx(0.01))  # resumed after the block


def test_two_monitors_in_one_period_the_first_on_in_file_order_wins() -> None:
    text = DEFS + (
        "arm   #=====\nslip  ~~~~~~\nbump  ~~~~~~\n@on bump\nidx #\n@end\n@on slip\nmid #\n@end\n"
    )
    result = run_fake(text, tick=0.1, holds={"slip": {7}, "bump": {7}})
    (monitor,) = records(result, "monitor")
    assert monitor["event"] == "bump"
    assert result.starts("idx") == [(2, pytest.approx(0.07))] and result.starts("mid") == []


def test_retry_runs_the_block_again_from_its_tick_1_until_its_max() -> None:
    text = DEFS + "arm   #==\nslip  ~~~\n@on slip\nback  #\n@retry max 2\n@end\nidx #\n"
    # The condition holds in the fifth period of every attempt: 3 attempts, then the error.
    holds = {5, 5 + 15, 5 + 30}
    result = run_fake(text, tick=0.1, holds={"slip": holds})
    assert [t for t, _ in result.starts("arm")] == [1, 3, 5]
    assert [k[4] for k in kinds(result) if k[0] == "monitor"] == [5, 20, 35]
    assert not result.summary.ok and result.starts("idx") == []
    message = str(result.summary.error)
    assert message.startswith(
        "'@retry max 2' on line 12 of fake.dial reached its max: the block on line 8 was "
        "preempted 3 times by the monitor '@on slip' (line 10 of fake.dial)"
    )
    assert records(result, "error")[0]["tick"] == 6


def test_retry_that_succeeds_goes_on_after_the_block() -> None:
    text = DEFS + "arm   #==\nslip  ~~~\n@on slip\nback  #\n@retry\n@end\nidx #\n"
    result = run_fake(text, tick=0.1, holds={"slip": {5}})
    assert result.summary.ok
    assert [o for *_, o in result.ends("arm")] == ["preempted", "done"]
    assert result.starts("idx") == [(6, pytest.approx(0.45))]


def test_abort_ends_the_run_with_an_error_naming_the_monitor() -> None:
    text = DEFS + 'arm   #==\nslip  ~~~\n@on !slip\n@abort "the thumb lost the bulb"\n@end\nidx #\n'
    result = run_fake(text, tick=0.1, holds={"slip": {1, 2}})
    assert not result.summary.ok and result.starts("idx") == []
    assert str(result.summary.error) == (
        "@abort on line 11 of fake.dial: the thumb lost the bulb (the monitor '@on !slip' "
        "(line 10 of fake.dial) fired at tick 1)"
    )
    (error,) = records(result, "error")
    assert error["event"] == "slip" and error["t"] == pytest.approx(0.03)


def test_a_monitor_inside_a_reaction() -> None:
    text = DEFS + (
        "arm   #==\nslip  ~~~\n@on slip\nback  #==\nbump  ~~~\n@on bump\nidx #\n@end\n@end\nmid #\n"
    )
    result = run_fake(text, tick=0.1, holds={"slip": {4}, "bump": {6}})
    monitors = [(r["event"], r["period"], r["tick"]) for r in records(result, "monitor")]
    assert monitors == [("slip", 4, 1), ("bump", 6, 2)]
    assert result.ends("back") == [(2, pytest.approx(0.06), "preempted")]
    assert result.starts("idx") == [(3, pytest.approx(0.06))]
    assert result.starts("mid") == [(4, pytest.approx(0.16))]


def test_an_indeterminate_run_stretching_its_tick_is_preempted_too() -> None:
    text = DEFS + "grab  #\nslip  ~\n@on slip\n@end\n"
    result = run_fake(
        text, tick=0.1, behaviours={"grab": Behaviour(duration=1.0)}, holds={"slip": {40}}
    )
    assert result.ends("grab") == [(1, pytest.approx(0.4), "preempted")]
    assert [r["stretch"] for r in records(result, "tick")] == [30]


def test_a_run_that_errors_in_the_period_a_monitor_fires_aborts() -> None:
    text = DEFS + "grab  #=\nslip  ~~\n@on slip\n@end\n"
    bad = Behaviour(duration=0.05, outcomes=[Outcome.ERROR], message="tendon slipped")
    result = run_fake(text, tick=0.1, behaviours={"grab": bad}, holds={"slip": {5}})
    assert not result.summary.ok and "tendon slipped" in str(result.summary.error)
    assert records(result, "monitor") == []


@pytest.mark.parametrize("seed", [1, 2])
def test_reactions_do_not_depend_on_trio_task_order(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    import trio._core._run as trio_run  # private: the only way to pick trio's task order

    text = DEFS + "arm   #==\nslip  ~~~\n@on slip\nback  #\n@retry\n@end\n" + BASIC.split(DEFS)[1]
    reference = run_fake(text, tick=0.1, holds={"slip": {5, 23, 77}}).log.records
    monkeypatch.setattr(trio_run, "_ALLOW_DETERMINISTIC_SCHEDULING", True)
    trio_run._r.seed(seed)
    assert run_fake(text, tick=0.1, holds={"slip": {5, 23, 77}}).log.records == reference
