"""A link that fails safe, and a server that takes no nonsense (issue 23's acceptance),
with a real ``dial serve`` on 127.0.0.1; the bad-input client is written with the
``websockets`` package from docs/remote.md alone."""

from __future__ import annotations

import json
import math
import os
import signal
import time
from pathlib import Path

import pytest

from tests.remote.helpers import Server, operator, run_operator, server, wait_for

websockets = pytest.importorskip("websockets.sync.client")


def _ticks(srv: Server, least: int) -> bool:
    return any(r["kind"] == "tick" and int(str(r["tick"])) >= least for r in srv.records())


def _recv(ws: object, *skip: str) -> dict[str, object]:
    """The next message that is not a heartbeat, telemetry or log records (nor ``skip``),
    within 30 s."""
    end = time.monotonic() + 30
    while True:
        assert time.monotonic() < end, "no reply within 30 s"
        msg = json.loads(ws.recv(timeout=10))  # type: ignore[attr-defined]
        if msg["type"] not in ("heartbeat", "telemetry", "records", *skip):
            return dict(msg)


def _status(srv: Server) -> dict[str, object]:
    token = srv.token_file.read_text().strip()
    with websockets.connect(srv.url) as ws:
        ws.send(json.dumps({"v": 1, "type": "hello", "token": token, "role": "observer"}))
        assert _recv(ws)["type"] == "welcome"
        ws.send(json.dumps({"v": 1, "type": "status"}))
        return _recv(ws)


def test_a_killed_operator_leaves_the_robot_holding_then_a_new_session_runs(
    tmp_path: Path,
) -> None:
    with server(tmp_path, "--watchdog", "1", pace=0.5) as srv:
        with operator(srv, "pour.dial") as op:
            assert wait_for(lambda: _ticks(srv, 6), 60)
            os.killpg(op.pid, signal.SIGKILL)
            killed = time.monotonic()
        assert wait_for(lambda: any(r["kind"] == "lost" for r in srv.records()), 3)
        assert time.monotonic() - killed < 1.0 + 1.0
        time.sleep(max(0.0, killed + 1.0 + 0.01 * 0.5 + 0.3 - time.monotonic()))
        first = _status(srv)
        time.sleep(1.0)
        second = _status(srv)
        assert first["state"] == "lost" and first["t"] != second["t"]  # the physics goes on
        moved = math.dist(first["tool"], second["tool"])  # type: ignore[arg-type]
        turned = max(
            abs(a - b)
            for key in ("arm", "hand")
            for a, b in zip(first[key], second[key], strict=True)  # type: ignore[call-overload]
        )
        assert moved < 1.0 and turned < 0.01, (moved, turned)
        records = srv.records()
        stopped = [r for r in records if r["kind"] == "interrupted"]
        assert stopped and stopped[0]["signal"] == "link lost"
        code, summary, err = run_operator(srv, "reactions.dial")
        assert code == 0, err
        assert summary is not None and summary["ok"] is True


def test_a_killed_robot_is_reported_within_the_watchdog_and_a_second(tmp_path: Path) -> None:
    with server(tmp_path, "--watchdog", "1", pace=0.5) as srv, operator(srv, "pour.dial") as op:
        assert wait_for(lambda: _ticks(srv, 4), 60)
        os.killpg(srv.proc.pid, signal.SIGKILL)
        killed = time.monotonic()
        _, err = op.communicate(timeout=10)
        elapsed = time.monotonic() - killed
    assert op.returncode == 1
    assert elapsed <= 1.0 + 1.0, elapsed
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "lost the robot" in lines[0], err


def test_a_blackholed_robot_is_reported_and_the_robot_holds(tmp_path: Path) -> None:
    with server(tmp_path, "--watchdog", "1", pace=0.5) as srv:
        code, _, err = run_operator(
            srv, "pour.dial", "--link", "blackhole=3s", log=tmp_path / "op.jsonl"
        )
        assert wait_for(lambda: any(r["kind"] == "lost" for r in srv.records()), 3)
    assert code == 1 and len(err.strip().splitlines()) == 1 and "lost the robot" in err
    op = [json.loads(line) for line in (tmp_path / "op.jsonl").read_text().splitlines()]
    connected = next(r for r in op if r["kind"] == "connected")
    lost = next(r for r in op if r["kind"] == "lost")
    assert float(lost["wall"]) - float(connected["wall"]) <= 3.0 + 1.0 + 1.0


def test_ctrl_c_at_the_operator_stops_the_robot(tmp_path: Path) -> None:
    with server(tmp_path, pace=0.5) as srv, operator(srv, "pour.dial") as op:
        assert wait_for(lambda: _ticks(srv, 4), 60)
        op.send_signal(signal.SIGINT)
        _, err = op.communicate(timeout=10)
        records = srv.records()
    assert op.returncode == 130, err
    stopped = [r for r in records if r["kind"] == "interrupted"]
    assert stopped and stopped[0]["signal"] == "the operator's stop"
    assert not any(r["kind"] == "lost" for r in records)


def test_bad_input_gets_the_documented_errors_and_the_server_keeps_serving(
    tmp_path: Path,
) -> None:
    with server(tmp_path, "--scene", "reactions", pace=0.2) as srv:
        token = srv.token_file.read_text().strip()
        with websockets.connect(srv.url) as ws:  # a wrong token: refused, closed
            ws.send(json.dumps({"v": 1, "type": "hello", "token": "nope", "role": "operator"}))
            assert _recv(ws)["code"] == "token"
        with websockets.connect(srv.url, max_size=None) as ws:
            ws.send(json.dumps({"v": 1, "type": "status"}))
            assert _recv(ws)["code"] == "order"  # hello first
            ws.send(json.dumps({"v": 1, "type": "hello", "token": token, "role": "operator"}))
            welcome = _recv(ws)
            assert welcome["type"] == "welcome" and welcome["session"] == 1
            ws.send(json.dumps({"v": 1, "type": "status"}))
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
            with websockets.connect(srv.url) as other:  # one operator at a time
                other.send(
                    json.dumps({"v": 1, "type": "hello", "token": token, "role": "operator"})
                )
                assert _recv(other)["code"] == "busy"
            ws.send(json.dumps({"v": 1, "type": "stop", "seq": 1, "id": "s1"}))
            assert _recv(ws) == {"v": 1, "type": "ack", "seq": 1, "id": "s1"}
            assert _recv(ws)["type"] == "finished"
        assert not any(r["kind"] == "scene" for r in srv.records())  # nothing ran
        code, _summary, err = run_operator(srv, "reactions.dial")
        assert code == 0, err


def test_a_block_after_its_tick_is_refused_late_and_the_robot_holds(tmp_path: Path) -> None:
    """A client of its own opens a block session, sends the first block, then one tagged
    at a tick the robot has passed: ``late``; one chained after that: ``dropped``."""
    import dial
    from dial.parser.script import TBlock
    from dial.remote.blocks import describe
    from dial.remote.walk import upload

    script = dial.load("reactions.dial")
    blocks = [s for s in script.timeline if isinstance(s, TBlock)]
    with server(tmp_path, pace=0.2) as srv:
        token = srv.token_file.read_text().strip()
        with websockets.connect(srv.url) as ws:
            ws.send(json.dumps({"v": 1, "type": "hello", "token": token, "role": "operator"}))
            assert _recv(ws)["type"] == "welcome"

            def send(type_: str, seq: int, **fields: object) -> None:
                ws.send(json.dumps({"v": 1, "type": type_, "seq": seq, "id": f"c{seq}", **fields}))

            send("open", 1, script=upload(script), tick_length=0.1)
            assert _recv(ws)["type"] == "ack"
            assert _recv(ws)["checked"] is True
            first = describe(script, blocks[0])["block"]
            send("block", 2, tick=1, after=1, script=script.path, block=first)
            second = describe(script, blocks[1])["block"]
            send("block", 3, tick=2, after=2, script=script.path, block=second)
            send("block", 4, tick=40, after=3, script=script.path, block=second)
            replies = [_recv(ws) for _ in range(6)]
            by_seq = {(r["type"], r.get("seq")) for r in replies}
            assert {("ack", 2), ("ack", 3), ("ack", 4), ("result", 2)} <= by_seq
            refused = {r["seq"]: r for r in replies if r["type"] == "refused"}
            assert refused[3]["code"] == "late" and "holds" in str(refused[3]["message"])
            assert refused[4]["code"] == "dropped"
            send("stop", 5)
            while _recv(ws)["type"] != "finished":
                pass
        blocks_run = [r for r in srv.records() if r["kind"] == "block"]
    assert len(blocks_run) == 1  # the first only
