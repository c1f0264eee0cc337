"""The same script, scene, seed and tick give the same log and final state, whatever
order trio runs ready tasks in."""

from __future__ import annotations

import io
import json
import subprocess
import sys
from pathlib import Path

import pytest

from dial.engine import RunOptions, run
from dial.parser import load
from dial.scene import load_scene_names


def _run(path: Path, perturb: float = 0.0) -> tuple[str, list[float]]:
    """The log text without the summary's wall time (its one wall-clock field), and qpos."""
    sink = io.StringIO()
    script = load(path, loader=load_scene_names)
    result = run(script, RunOptions(log=sink, perturb_mm=perturb, seed=7))
    *lines, last = sink.getvalue().splitlines()
    summary = json.loads(last)
    assert summary["kind"] == "summary" and summary.pop("wall_time") >= 0
    return "\n".join([*lines, json.dumps(summary)]), result.final_qpos


def test_two_runs_give_identical_logs_and_state(short_script: Path) -> None:
    log_a, q_a = _run(short_script, perturb=5.0)
    log_b, q_b = _run(short_script, perturb=5.0)
    assert log_a == log_b
    assert q_a == q_b  # bit for bit
    kinds = {json.loads(line)["kind"] for line in log_a.splitlines()}
    assert {"scene", "start", "end", "tick"} <= kinds


@pytest.mark.parametrize("seed", [11, 12])
def test_log_is_independent_of_trio_task_order(
    short_script: Path, seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    import trio._core._run as trio_run  # private: the only way to choose trio's task order

    reference = _run(short_script)
    monkeypatch.setattr(trio_run, "_ALLOW_DETERMINISTIC_SCHEDULING", True)
    trio_run._r.seed(seed)
    assert _run(short_script) == reference


def test_cli_log_files_match_apart_from_wall_time(short_script: Path, tmp_path: Path) -> None:
    logs = []
    for name in ("a", "b"):
        out = tmp_path / f"{name}.jsonl"
        subprocess.run(
            [
                sys.executable,
                "-m",
                "dial.cli",
                "run",
                str(short_script),
                "--log",
                str(out),
                "--quiet",
            ],
            check=False,
        )
        records = [json.loads(line) for line in out.read_text().splitlines()]
        assert records[-1]["kind"] == "summary"
        records[-1].pop("wall_time")
        logs.append(records)
    assert logs[0] == logs[1]
