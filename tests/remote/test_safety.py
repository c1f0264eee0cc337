"""A link that fails safe, and a server that takes no nonsense (issue 23's acceptance),
with a real ``dial serve`` on 127.0.0.1; the clients of their own are written with the
``websockets`` package from docs/remote.md alone. The tests share one server where the
acceptance allows it (each starts when the robot is no longer under control)."""

from __future__ import annotations

import contextlib
import json
import math
import os
import signal
import stat
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from dial import load as dial_load
from dial.remote.telemetry import telemetry_every
from tests.remote.helpers import (
    Server,
    dial,
    first_line,
    kill,
    operator,
    robot_log,
    run_operator,
    server,
    spawn,
    wait_for,
)

websockets = pytest.importorskip("websockets.sync.client")
closed = pytest.importorskip("websockets.exceptions").ConnectionClosed
PACE = 0.5


def _send(ws: Any, type_: str, **fields: object) -> None:
    ws.send(json.dumps({"v": 1, "type": type_, **fields}))


def _recv(ws: Any, *skip: str) -> dict[str, object]:
    """The next message that is not a heartbeat, telemetry or log records (nor ``skip``),
    within 30 s."""
    end = time.monotonic() + 30
    while True:
        assert time.monotonic() < end, "no reply within 30 s"
        msg = json.loads(ws.recv(timeout=10))
        if msg["type"] not in ("heartbeat", "telemetry", "records", *skip):
            return dict(msg)


def _hello(ws: Any, srv: Server, role: str = "operator") -> dict[str, object]:
    _send(ws, "hello", token=srv.token_file.read_text().strip(), role=role)
    return _recv(ws)


def _status(srv: Server) -> dict[str, object]:
    with websockets.connect(srv.url) as ws:
        assert _hello(ws, srv, "observer")["type"] == "welcome"
        _send(ws, "status")
        return _recv(ws)


@pytest.fixture(scope="module")
def shared(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    with server(tmp_path_factory.mktemp("robot"), "--watchdog", "1", pace=PACE) as srv:
        yield srv


@pytest.fixture
def robot(shared: Server) -> Server:
    """The shared server, once no session controls its robot."""
    assert shared.proc.poll() is None, "the shared dial serve has died"
    free = ("idle", "finished", "lost", "stopped", "rejected")
    assert wait_for(lambda: _status(shared)["state"] in free, 15), "the robot is still busy"
    return shared


def _ticks(srv: Server, session: int, least: int) -> bool:
    return any(
        r["kind"] == "tick" and int(str(r["tick"])) >= least
        for r in robot_log(srv.records(), session)
    )


def test_a_killed_operator_leaves_the_robot_holding_then_a_new_session_runs(
    robot: Server,
) -> None:
    """After kill -9 of the operator the robot logs 'link lost' within the watchdog time,
    holds (1 mm, 0.01 rad), and its uploaded script does nothing more; then a new session,
    on the scene set up anew, succeeds."""
    session = robot.last_session() + 1
    with operator(robot, "pour.dial", "--no-predict") as op:
        assert wait_for(lambda: _ticks(robot, session, 6), 60)
        os.killpg(op.pid, signal.SIGKILL)
        killed = time.monotonic()

    def lost() -> bool:
        return any(r["kind"] == "lost" for r in _session(robot, session))

    assert wait_for(lost, 3)
    assert time.monotonic() - killed < 1.0 + 1.0
    time.sleep(max(0.0, killed + 1.0 + 0.01 * PACE + 0.3 - time.monotonic()))
    first = _status(robot)
    time.sleep(1.0)
    second = _status(robot)
    assert first["state"] == "lost" and first["t"] != second["t"]  # the physics goes on
    moved = math.dist(first["tool"], second["tool"])  # type: ignore[arg-type]
    turned = max(
        abs(a - b)
        for key in ("arm", "hand")
        for a, b in zip(first[key], second[key], strict=True)  # type: ignore[call-overload]
    )
    assert moved < 1.0 and turned < 0.01, (moved, turned)
    records = _session(robot, session)
    stopped = [r for r in records if r["kind"] == "interrupted"]
    assert stopped and stopped[0]["signal"] == "link lost"
    # The script stops at the end of the control period it is in: what that period's tick
    # boundary started is the last thing it does (no reaction, no later block).
    lost = next(r for r in records if r["kind"] == "lost")
    assert int(str(stopped[0]["tick"])) <= int(str(lost["tick"])) + 1
    after = records[records.index(stopped[0]) :]
    assert not any(r["kind"] in ("start", "block", "condition", "monitor") for r in after)
    code, summary, err = run_operator(robot, "reactions.dial", "--no-predict")
    assert code == 0, err
    assert summary is not None and summary["ok"] is True
    scene = robot_log(robot.records(), robot.last_session())[0]
    assert scene["kind"] == "scene" and scene["scene"] == "reactions"  # set up anew


def _session(srv: Server, number: int) -> list[dict[str, object]]:
    """One session's records, link records included."""
    out, current = [], 0
    for r in srv.records():
        if r["kind"] == "session":
            current = int(str(r["session"]))
        if current == number:
            out.append(r)
    return out


def test_a_blackholed_robot_is_reported_and_the_robot_holds(robot: Server, tmp_path: Path) -> None:
    log = tmp_path / "op.jsonl"
    code, _, err = run_operator(robot, "pour.dial", "--link", "blackhole=3s", log=log)
    session = robot.last_session()
    assert wait_for(lambda: any(r["kind"] == "lost" for r in _session(robot, session)), 3)
    assert code == 1 and len(err.strip().splitlines()) == 1 and "lost the robot" in err
    op = [json.loads(line) for line in log.read_text().splitlines()]
    connected = next(r for r in op if r["kind"] == "connected")
    lost = next(r for r in op if r["kind"] == "lost")
    assert float(lost["wall"]) - float(connected["wall"]) <= 3.0 + 1.0 + 1.0


def test_ctrl_c_at_the_operator_stops_the_robot(robot: Server) -> None:
    session = robot.last_session() + 1
    with operator(robot, "pour.dial", "--no-predict") as op:
        assert wait_for(lambda: _ticks(robot, session, 4), 60)
        op.send_signal(signal.SIGINT)
        _, err = op.communicate(timeout=10)
    records = _session(robot, session)
    assert op.returncode == 130, err
    stopped = [r for r in records if r["kind"] == "interrupted"]
    assert stopped and stopped[0]["signal"] == "the operator's stop"
    assert not any(r["kind"] == "lost" for r in records)


def test_heartbeats_flow_both_ways_and_silence_loses_the_link(robot: Server) -> None:
    """The robot sends a heartbeat every 0.25 s; the operator's heartbeats alone keep its
    session for twice the watchdog time; then silence loses it (the robot closes the
    connection; an operator that reconnects to the session gets its end)."""
    with websockets.connect(robot.url) as ws:
        welcome = _hello(ws, robot)
        assert welcome["type"] == "welcome"
        session = int(str(welcome["session"]))
        beats, end = 0, time.monotonic() + 2.0
        while time.monotonic() < end:
            _send(ws, "heartbeat")
            with contextlib.suppress(TimeoutError):
                beats += json.loads(ws.recv(timeout=0.2))["type"] == "heartbeat"
        assert beats >= 5
        _send(ws, "status")
        assert _recv(ws)["state"] == "ready"  # not lost: heartbeats count
        time.sleep(1.5)  # silence: the robot logs 'link lost' and closes the connection
        with pytest.raises(closed):
            for _ in range(100):
                ws.recv(timeout=5)
    assert _status(robot)["state"] == "lost"
    assert any(r["kind"] == "lost" for r in _session(robot, session))


def test_bad_input_gets_the_documented_errors_and_the_server_keeps_serving(
    robot: Server,
) -> None:
    """A wrong token runs nothing; malformed JSON, a 10 MB frame, an unknown type, a wrong
    version each get their error and the connection stays; a second operator is refused;
    a good session afterwards succeeds, through a slow link: its telemetry decimated."""
    from dial.remote.walk import upload

    before = robot.records()
    with websockets.connect(robot.url) as ws:  # a wrong token: refused, closed, nothing runs
        _send(ws, "hello", token="nope", role="operator")
        script = upload(dial_load("reactions.dial"))
        with contextlib.suppress(closed):  # (sent at once, on a connection being closed)
            _send(ws, "run", seq=1, id="c1", tick=1, after=0, script=script, tick_length=0.1)
        assert _recv(ws)["code"] == "token"
        with pytest.raises(closed):
            for _ in range(100):
                ws.recv(timeout=5)
    assert robot.records() == before  # no session, no scene, no run
    with websockets.connect(robot.url, max_size=None) as ws:
        _send(ws, "status")
        assert _recv(ws)["code"] == "order"  # hello first
        welcome = _hello(ws, robot)
        assert welcome["type"] == "welcome"
        _send(ws, "status")
        assert _recv(ws)["state"] == "ready"
        for frame, code in [
            ("{not json", "malformed"),
            ("x" * 10_000_000, "too_large"),
            (json.dumps({"v": 1, "type": "launch"}), "unknown_type"),
            (json.dumps({"v": 99, "type": "status"}), "version"),
            (json.dumps({"v": 1, "type": "run", "seq": 1}), "invalid"),
        ]:
            ws.send(frame)
            reply = _recv(ws)
            assert (reply["type"], reply["code"]) == ("error", code)
            assert isinstance(reply["message"], str) and reply["message"]
        with websockets.connect(robot.url) as other:  # one operator at a time
            assert _hello(other, robot)["code"] == "busy"
        _send(ws, "stop", seq=1, id="s1")
        assert _recv(ws) == {"v": 1, "type": "ack", "seq": 1, "id": "s1"}
        assert _recv(ws)["type"] == "finished"
    assert not any(r["kind"] == "scene" for r in _session(robot, int(str(welcome["session"]))))
    bandwidth = 32_000.0
    code, summary, err = run_operator(
        robot, "reactions.dial", "--no-predict", "--link", f"bandwidth={bandwidth:g}bps"
    )
    assert code == 0, err
    assert summary is not None and summary["ok"] is True
    periods = round(float(str(summary["sim_time"])) / 0.01)
    every = telemetry_every(0.01, PACE, bandwidth)
    assert every > 30  # at most half the link's bandwidth: 420-byte samples 0.2 s apart
    remote = summary["remote"]
    assert isinstance(remote, dict) and 1 <= remote["telemetry"] <= periods // every + 1


def test_a_block_after_its_tick_is_refused_late_and_the_robot_holds(robot: Server) -> None:
    """A client of its own opens a block session, sends the first block, then one tagged
    at a tick the robot has passed: ``late``; one chained after that: ``dropped``."""
    import dial
    from dial.parser.script import TBlock
    from dial.remote.blocks import describe
    from dial.remote.walk import upload

    script = dial.load("reactions.dial")
    blocks = [s for s in script.timeline if isinstance(s, TBlock)]
    with websockets.connect(robot.url) as ws:
        welcome = _hello(ws, robot)
        assert welcome["type"] == "welcome"

        def command(type_: str, seq: int, **fields: object) -> None:
            _send(ws, type_, seq=seq, id=f"c{seq}", **fields)

        command("open", 1, script=upload(script), tick_length=0.1)
        assert _recv(ws)["type"] == "ack"
        assert _recv(ws)["checked"] is True
        first = describe(script, blocks[0])["block"]
        command("block", 2, tick=1, after=1, script=script.path, block=first)
        second = describe(script, blocks[1])["block"]
        command("block", 3, tick=2, after=2, script=script.path, block=second)
        command("block", 4, tick=40, after=3, script=script.path, block=second)
        replies = [_recv(ws) for _ in range(6)]
        by_seq = {(r["type"], r.get("seq")) for r in replies}
        assert {("ack", 2), ("ack", 3), ("ack", 4), ("result", 2)} <= by_seq
        refused = {r["seq"]: r for r in replies if r["type"] == "refused"}
        assert refused[3]["code"] == "late" and "holds" in str(refused[3]["message"])
        assert refused[4]["code"] == "dropped"
        command("stop", 5)
        while _recv(ws)["type"] != "finished":
            pass
    session = int(str(welcome["session"]))
    assert len([r for r in _session(robot, session) if r["kind"] == "block"]) == 1


def test_a_killed_robot_is_reported_within_the_watchdog_and_a_second(tmp_path: Path) -> None:
    with (
        server(tmp_path, "--watchdog", "1", pace=PACE) as srv,
        operator(srv, "pour.dial", "--no-predict") as op,
    ):
        assert wait_for(lambda: _ticks(srv, 1, 4), 60)
        os.killpg(srv.proc.pid, signal.SIGKILL)
        killed = time.monotonic()
        _, err = op.communicate(timeout=10)
        elapsed = time.monotonic() - killed
    assert op.returncode == 1
    assert elapsed <= 1.0 + 1.0, elapsed
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "lost the robot" in lines[0], err


def test_the_token_file_is_written_beside_the_log_or_in_the_state_folder(
    tmp_path: Path,
) -> None:
    """Without --token-file: beside --log, else in $XDG_STATE_HOME/dial; new, mode 0600,
    and the server says where. It listens on loopback unless --listen says otherwise."""
    state = tmp_path / "state"
    beside = dial("serve", "--listen", "127.0.0.1:0", "--log", str(tmp_path / "robot.jsonl"))
    started = [
        spawn(beside, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL),
        spawn(
            dial("serve", "--listen", "127.0.0.1:0"),
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            extra_env={"XDG_STATE_HOME": str(state)},
        ),
    ]
    try:
        said = [first_line(proc) for proc in started]
    finally:
        for proc in started:
            kill(proc)
    for line, token in zip(said, (tmp_path / "robot.token", state / "dial" / "token"), strict=True):
        assert f"new token written to {token}" in line
        assert stat.S_IMODE(token.stat().st_mode) == 0o600 and len(token.read_text()) > 30
    from dial.cli import build_parser

    assert build_parser().parse_args(["serve"]).listen == "127.0.0.1:8765"


def test_an_upload_that_does_not_check_in_the_robots_world_is_rejected_before_anything_moves(
    tmp_path: Path,
) -> None:
    """The robot checks an uploaded script against its own world (here --scene reactions,
    where pour's programs and poses do not exist): every diagnostic goes back, with its
    caret, and the scene is never set up."""
    with server(tmp_path, "--scene", "reactions", pace=PACE) as srv:
        code, summary, err = run_operator(srv, "pour.dial", "--no-predict")
        assert _status(srv)["state"] == "rejected"
        records = srv.records()
    assert code == 1 and summary is not None and summary["ok"] is False
    assert "unknown program 'get_top' in scene 'reactions'" in err and "^" in err
    assert not any(r["kind"] in ("scene", "start") for r in records)
