"""`dial run` end to end: exit statuses and messages for errors, timeouts and interrupts."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from dial.cli import main

DIAL = [sys.executable, "-m", "dial.cli"]


def _script(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "t.dial"
    path.write_text("@scene surface\n@tick 0.1\n" + body)
    return path


def test_bad_parameter_is_reported_before_anything_moves(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _script(tmp_path, '% grab grasp_force "0x0666_0x0222 400"\ngrab #\n')
    assert main(["run", str(path), "--log", str(tmp_path / "log.jsonl")]) == 1
    err = capsys.readouterr().err
    assert f"{path}:3:35: event 'grab': bad force: 400 is out of range" in err
    assert not (tmp_path / "log.jsonl").exists()  # it never started


def test_unknown_pose_names_the_event_and_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _script(tmp_path, '% p hand_pose "opne_hand"\np #\n')
    assert main(["run", str(path)]) == 1
    err = capsys.readouterr().err
    assert f"{path}:3:16: event 'p': unknown pose 'opne_hand' in scene 'surface'" in err
    assert "did you mean 'open_hand'" in err


def test_grasp_timeout_aborts_naming_event_line_and_tick(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _script(
        tmp_path,
        '% open hand_pose "open_hand"\n'
        '% grab grasp_force "0x0666_0x0222 4N" speed=0.05 timeout=0.3s\n'
        "open #-\ngrab   #\n",
    )
    log = tmp_path / "log.jsonl"
    assert main(["run", str(path), "--log", str(log), "--json"]) == 1
    captured = capsys.readouterr()
    message = f"event 'grab' (defined on line 4 of {path}) ended timeout at tick 3"
    assert message in captured.err
    summary = json.loads(captured.out.splitlines()[-1])
    assert summary["ok"] is False and message in summary["error"]
    records = [json.loads(line) for line in log.read_text().splitlines()]
    assert [r["kind"] for r in records[-2:]] == ["error", "summary"]


def _running(tmp_path: Path) -> tuple[subprocess.Popen[bytes], Path]:
    """A long `dial run --log` that has got going (five ticks logged)."""
    body = '% to puma_command "ex to_block"\n% back puma_command "ex retract_arm"\n'
    body += "@repeat 200\nto   #====\nback      #====\n@end\n"
    path = _script(tmp_path, body)
    log = tmp_path / "log.jsonl"
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen(
        [*DIAL, "run", str(path), "--log", str(log), "--quiet"], env=env, stderr=subprocess.PIPE
    )
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and proc.poll() is None:
        if log.exists() and log.read_text().count('"kind":"tick"') >= 5:
            return proc, log
        time.sleep(0.05)
    proc.kill()
    raise AssertionError("the run did not start")


@pytest.mark.parametrize(
    ("signals", "status", "name"),
    [
        ((signal.SIGINT,), 130, "SIGINT"),
        ((signal.SIGTERM,), 143, "SIGTERM"),
        ((signal.SIGINT, signal.SIGINT), 130, "SIGINT"),  # the second 50 ms later
        ((signal.SIGTERM, signal.SIGINT), 143, "SIGTERM"),
    ],
)
def test_signals_end_the_run_cleanly_with_a_complete_log(
    tmp_path: Path, signals: tuple[int, ...], status: int, name: str
) -> None:
    proc, log = _running(tmp_path)
    sent = time.monotonic()
    for k, sig in enumerate(signals):
        if k:
            time.sleep(0.05)
        proc.send_signal(sig)
    assert proc.wait(timeout=60) == status
    assert time.monotonic() - sent < 20  # generous: the machine is shared
    assert proc.stderr is not None
    err = proc.stderr.read().decode()
    assert err == f"dial: interrupted by {name}; every effector holds its pose\n"
    records = [json.loads(line) for line in log.read_text().splitlines()]  # all complete
    assert [r["kind"] for r in records[-2:]] == ["interrupted", "summary"]
    assert records[-2]["signal"] == name and records[-1]["interrupted"] == name
    ticks = [r for r in records if r["kind"] == "tick"]
    assert records[-2]["t"] <= ticks[-1]["t1"] + 0.5  # stopped within the tick it was in


def test_a_drive_beyond_a_joint_limit_at_run_time_is_a_warning_not_a_silent_done(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Within joint 3's whole range (270 deg), so check accepts it; from the surface scene's
    # home the target lies beyond the lower limit: the arm stops there and says so.
    path = _script(tmp_path, '% d3 puma_command "drive 3 -200"\nd3 #====\n')
    log = tmp_path / "log.jsonl"
    main(["run", str(path), "--log", str(log)])
    message = (
        "DRIVE 3 -200 (drive): the target -404.6 deg is 179.6 deg beyond joint 3's lower "
        "limit (-225.0 deg); it stops there"
    )
    records = [json.loads(line) for line in log.read_text().splitlines()]
    (warning,) = [r for r in records if r["kind"] == "warning"]
    assert (warning["event"], warning["tick"], warning["message"]) == ("d3", 5, message)
    out = capsys.readouterr().out.splitlines()
    assert out[1:3] == ["  tick    5  d3     done", f"  tick    5  warning: {message}"]
