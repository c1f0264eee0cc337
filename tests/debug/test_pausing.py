"""Pausing a run: breakpoints, stepping and the paused commands (DESIGN 6.1)."""

from __future__ import annotations

import io
import os
import pty
import select
import subprocess
import sys
import time
from pathlib import Path

import pytest
import trio
import trio.testing

import dial
from dial.cli import main
from dial.debug import ScriptedConsole, Session, parse_break
from dial.parser import check_text
from dial.recording.frames import Batch
from dial.recording.observers import Recorder
from dial.scheduler.log import EventLog
from dial.scheduler.runner import Runner
from dial.scheduler.signals import StopRequest
from dial.testing import FakeFactory, FakeRobot

DIAL = [sys.executable, "-m", "dial.cli"]
POUR = [*DIAL, "run", "pour.dial", "--break", "grabpit", "--quiet"]


def _fake_session(text: str, commands: list[str], **kwargs: object) -> tuple[Session, object]:
    script = check_text(text, "fake.dial")
    robot, log, stop = FakeRobot(), EventLog(), StopRequest()
    console = ScriptedConsole(commands)
    ticks: list[int] = []
    session = Session(
        stop, console, where=lambda: f"tick {ticks[-1] if ticks else 0}", top=script.path, **kwargs
    )
    runner = Runner(robot, FakeFactory(robot), 0.1, log, stop=stop, hooks=session)
    summary = trio.run(runner.run, script, clock=trio.testing.MockClock(autojump_threshold=0))
    return session, (summary, console, robot, log)


TEXT = '% a puma_command "moves x"\n% b hand_pose "p"\na #==\nb   #=\n'


def test_break_at_a_tick_then_step_a_period_and_a_tick() -> None:
    _, (summary, console, robot, _) = _fake_session(
        TEXT, ["period", "tick", "continue"], breaks=[parse_break("tick:2", {"a", "b"})]
    )
    assert summary.ok
    text = "".join(console.transcript)
    assert text.count("paused at") == 3
    assert "--break tick:2" in text and "one period" in text and ": step" in text
    # Paused before tick 2's period 11, after it, and at the start of tick 3.
    assert len(robot.trace) == 40


def test_break_on_an_event_pauses_before_it_starts() -> None:
    _, (summary, console, _, _log) = _fake_session(
        TEXT, ["continue"], breaks=[parse_break("b", {"a", "b"})]
    )
    assert summary.ok and "--break b (line 4" in "".join(console.transcript)


def test_a_break_in_a_called_script_names_its_file(tmp_path: Path) -> None:
    from .test_resume import SUB, TOP

    (tmp_path / "top.dial").write_text(TOP)
    (tmp_path / "sub.dial").write_text(SUB)
    console = ScriptedConsole(["continue", "continue"])
    dial.run(tmp_path / "top.dial", breaks=["to", "open"], console=console)
    text = "".join(console.transcript)
    assert "--break to (line 6)" in text and "--break open (sub.dial:6)" in text


def test_quit_stops_the_run_with_every_effector_held() -> None:
    _, (summary, _, robot, log) = _fake_session(TEXT, ["quit"], step=True)
    assert summary.interrupted == "quit" and robot.held
    assert log.records[-1]["kind"] == "interrupted"


def test_end_of_commands_lets_the_run_finish() -> None:
    _, (summary, console, _, _) = _fake_session(TEXT, ["tick"], step=True)
    assert summary.ok
    assert "end of commands: the run goes on without pausing" in "".join(console.transcript)


def test_a_save_asked_for_after_the_last_block_is_not_lost_silently() -> None:
    session, (summary, console, _, _) = _fake_session(
        TEXT, ["save late.state", "continue"], breaks=[parse_break("tick:2", {"a", "b"})]
    )
    assert summary.ok and session.saved == []
    assert session.unsaved == Path("late.state")
    assert "(if the run starts another block)" in "".join(console.transcript)


def test_a_save_that_never_came_is_exit_1(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # retract_arm runs in pour.dial's last block: a save asked for there has no boundary
    # to wait for.
    state = tmp_path / "p.state"
    monkeypatch.setattr(sys, "stdin", io.StringIO(f"save {state}\ncontinue\n"))
    assert main(["run", "pour.dial", "--break", "retract_arm", "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err == f"dial: save {state}: the run started no block after it; nothing was saved\n"
    assert not state.exists()


def test_a_scripted_session_through_stdin() -> None:
    commands = "state\ntick\nbogus\ncontinue\n"
    done = subprocess.run(POUR, input=commands, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    out = done.stdout
    assert "paused at tick 57, t = 15.070 s: --break grabpit (line 136)" in out
    assert "(dial) state\ntick 57, t = 15.070 s" in out
    for part in ("running:", "latest outcomes:", "tool: x", "thumb", "no contact"):
        assert part in out, part
    assert "(dial) tick\npaused at tick 58" in out
    assert "unknown command 'bogus'; commands: continue, tick, period, state" in out


def _read_until(fd: int, marker: bytes, seen: bytearray, start: int, deadline: float) -> int:
    """Read until ``marker`` appears in ``seen`` after ``start``; the index just past it."""
    while (found := seen.find(marker, start)) < 0:
        if time.monotonic() > deadline:
            raise AssertionError(f"no {marker!r} in {bytes(seen[start:][-500:])!r}")
        ready, _, _ = select.select([fd], [], [], 0.5)
        if ready:
            try:
                seen += os.read(fd, 4096)
            except OSError:
                break
    return found + len(marker)


def test_a_session_at_a_terminal() -> None:
    leader, follower = pty.openpty()
    proc = subprocess.Popen(POUR, stdin=follower, stdout=follower, stderr=follower, close_fds=True)
    os.close(follower)
    seen = bytearray()
    deadline = time.monotonic() + 600
    try:
        at = _read_until(leader, b"(dial) ", seen, 0, deadline)
        assert b"--break grabpit" in seen
        os.write(leader, b"state\n")
        at = _read_until(leader, b"tendon differential", seen, at, deadline)
        at = _read_until(leader, b"(dial) ", seen, at, deadline)
        os.write(leader, b"tick\n")
        at = _read_until(leader, b"paused at tick 58", seen, at, deadline)
        at = _read_until(leader, b"(dial) ", seen, at, deadline)
        os.write(leader, b"continue\n")
        assert proc.wait(timeout=600) == 0
    finally:
        proc.kill()
        os.close(leader)


def test_show_numbers_blocks_as_the_run_counts_them() -> None:
    from dial.parser.timeline import expand
    from dial.testing import run_fake

    text = TEXT + "@repeat 3\na #\n\nb #=\n@end\na #=\n"
    script = check_text(text, "fake.dial")
    shown = [(s.block, s.line) for s in expand(script).sections if s.block is not None]
    ran = [(r["number"], r["line"]) for r in run_fake(script).log.of("block")]
    assert shown == ran and len(ran) == 8


class _Sink:
    """A rerun sink that keeps the simulated time of every frame sent to the viewer."""

    batch = 250  # frames per send: without the pause's own send, none would be out yet

    def __init__(self) -> None:
        self.sent: list[int] = []

    def scene(self, *args: object) -> None:
        pass

    def record(self, *args: object) -> None:
        pass

    def frames(self, batch: Batch) -> None:
        self.sent += [int(t) for t in batch.time_ns]

    def close(self) -> None:
        pass


class _Watching(ScriptedConsole):
    """Notes, at each command asked for, the last frame the viewer has been sent."""

    def __init__(self, commands: list[str], sink: _Sink) -> None:
        super().__init__(commands)
        self.sink, self.shown = sink, list[int | None]()

    async def read(self, prompt: str, stop: StopRequest) -> str | None:
        self.shown.append(self.sink.sent[-1] if self.sink.sent else None)
        return await super().read(prompt, stop)


def test_a_live_recording_shows_the_paused_state() -> None:
    sink = _Sink()
    console = _Watching(["period", "continue"], sink)
    recorder = Recorder(sink, "pour")  # type: ignore[arg-type]  # the sink's four methods
    dial.run("pour.dial", breaks=["tick:3"], console=console, observers=[recorder])
    # Paused at the start of tick 3 (t = 0.5 s), then one period on, mid-tick (0.51 s, a
    # period the recording's 50 Hz would skip): the viewer has each moment while paused.
    assert console.shown == [500_000_000, 510_000_000]
