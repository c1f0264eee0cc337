"""What the task scripts' reaction tests share: run a script with one documented push and
check, in its log, that the monitor fired, the watched run stopped where it was, the reaction
ran and the watched run went again to the end (docs/scenes.md, the disturbance envelopes)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

import dial
from dial.cli import main


def ended(result: dial.RunResult, event: str) -> list[dict[str, Any]]:
    return [r for r in result.log.of("end") if r["event"] == event]


def check_recovery(
    script: Path,
    push: str,
    monitor: str,
    watched: str,
    reaction: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> dict[str, Any]:
    """``dial run SCRIPT --disturb PUSH`` exits 0 and its log shows the recovery; the summary."""
    log = tmp_path / "run.jsonl"
    status = main(["run", str(script), "--disturb", push, "--log", str(log), "--json", "--quiet"])
    summary: dict[str, Any] = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert status == 0 and summary["ok"] is True, summary["error"]
    records = [json.loads(line) for line in log.read_text().splitlines()]
    kinds = [(r["kind"], r.get("event") or r.get("what")) for r in records]
    pushed = kinds.index(("disturb", push))
    fired = kinds.index(("monitor", monitor))
    assert pushed < fired  # the finger felt the push on the way down
    after = [(k, e, r.get("outcome")) for (k, e), r in zip(kinds, records, strict=True)][fired:]
    assert after[1] == ("end", watched, "preempted")  # stopped where it was
    started = [e for k, e, _ in after if k == "start"]
    assert started[0] == reaction  # the reaction's first run
    again = after.index(("start", watched, None))
    assert ("end", watched, "done") in after[again:]  # the retried descent went down
    return summary


def without_reactions(script: Path, watch: str, resume: str, tmp_path: Path) -> Path:
    """A copy of ``script`` with its watches and ``@on`` blocks cut out: from the ``watch``
    line (its first watched line) up to the comment ``resume`` that follows them."""
    first, rest = script.read_text().split(watch, 1)
    bare = tmp_path / f"{script.stem}_without_on.dial"
    bare.write_text(first + "\n" + rest[rest.index(resume) :])
    return bare
