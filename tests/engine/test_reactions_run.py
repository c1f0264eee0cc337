"""Monitors on the MuJoCo robot: scripts/reactions.dial, as docs/language.md tells it."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

import dial
from dial.engine import RunResult

from ..conftest import ROOT

SCRIPT = ROOT / "scripts" / "reactions.dial"


@pytest.fixture(scope="module")
def watched() -> RunResult:
    return dial.run(SCRIPT)


def test_the_monitor_fires_at_the_touch_and_the_reaction_follows(watched: RunResult) -> None:
    assert watched.ok, watched.details
    (monitor,) = watched.log.of("monitor")
    assert {k: monitor[k] for k in ("event", "tick", "t", "period", "step")} == {
        "event": "touch",
        "tick": 16,
        "t": 1.59,
        "period": 159,
        "step": 795,
    }
    ends = {r["event"]: (r["tick"], r["t"], r["outcome"]) for r in watched.log.of("end")}
    assert ends["down"] == (16, 1.59, "preempted")
    assert ends["note"] == (17, 1.59, "done") and ends["press"] == (17, 1.69, "done")
    # The monitor fired at the first physics step whose reading passed the threshold: the
    # point recorded in the reaction lies on the block's top face (80 mm block on a table).
    note = next(r for r in watched.log.of("end") if r["event"] == "note")
    assert note["data"]["count"] == 1


def test_without_the_monitor_the_finger_crashes_into_the_block(tmp_path: Path) -> None:
    text = SCRIPT.read_text(encoding="utf-8")
    lines = [
        ln
        for ln in text.splitlines()
        if not ln.startswith(("touch ", "@on", "note ", "press ", "@end"))
    ]
    bare = tmp_path / "bare.dial"
    bare.write_text("\n".join(lines).replace("@scene reactions", "@scene reactions") + "\n")
    result = dial.run(bare)
    assert result.summary.ok and not result.ok
    assert not result.success["light_touch"] and "with" in result.details["light_touch"]


def test_a_run_with_a_reaction_does_not_depend_on_trio_task_order(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import trio._core._run as trio_run  # private: the only way to pick trio's task order

    def log() -> list[dict[str, object]]:
        sink = io.StringIO()
        dial.run(SCRIPT, log=sink)
        records = [json.loads(line) for line in sink.getvalue().splitlines()]
        records[-1].pop("wall_time")
        return records

    reference = log()
    monkeypatch.setattr(trio_run, "_ALLOW_DETERMINISTIC_SCHEDULING", True)
    for seed in (5, 6):
        trio_run._r.seed(seed)
        assert log() == reference
