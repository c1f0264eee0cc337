"""The per-tick summary, the verdict and the table, from hand-made trial results."""

from __future__ import annotations

from dial.tune import TrialResult, render_table, summarise, verdict


def _result(
    tick: float, ok: bool, time: float | None = 1.0, error: str | None = None
) -> TrialResult:
    failed = () if ok or error else ("upright",)
    return TrialResult(tick, 0, 0, ok, time, tick if time else None, failed, error)


def test_partial_success_is_not_reliable_and_times_are_of_successes() -> None:
    rows = summarise(
        [
            _result(0.2, True, 3.0),
            _result(0.1, True, 2.0),
            _result(0.1, False, 1.5),
            _result(0.2, True, 5.0),
            _result(0.2, True, 4.0),
            _result(0.1, False, None, "IK failed"),
        ]
    )
    assert [r.tick for r in rows] == [0.1, 0.2]
    short, long = rows
    assert (short.successes, short.trials, short.median_time, short.worst_time) == (1, 3, 2.0, 2.0)
    assert short.failed == {"upright": 1} and short.errors == {"IK failed": 1}
    assert (long.median_time, long.worst_time) == (4.0, 5.0)
    assert verdict(rows)[0].startswith("fastest reliable tick: 0.2 s (3/3 trials")


def test_without_a_reliable_tick_the_verdict_names_the_best_one() -> None:
    rows = summarise([_result(0.1, False), _result(0.2, True), _result(0.2, False)])
    assert verdict(rows) == ["no tick length reached 100 % success (best: 0.2 s with 1/2)"]


def test_table_shows_counts_and_dashes() -> None:
    rows = summarise([_result(0.1, False), _result(0.1, False, None, "boom")])
    text = render_table(rows, "title")
    assert text.splitlines()[0] == "title"
    line = next(x for x in text.splitlines() if x.strip().startswith("0.1"))
    assert line.split() == ["0.1", "0/2", "0", "%", "-", "-", "1x", "upright", "1x", "boom"]
    assert all(x == x.rstrip() for x in text.splitlines())
