"""Remote runs with a real ``dial serve`` on 127.0.0.1 (issue 23's acceptance): both splits
through a delayed link, split script equal to a local run, split block deterministic
without ``--lead``, a cut in the middle of a block, prediction, and ``--record``."""

from __future__ import annotations

import json
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from contextlib import ExitStack
from pathlib import Path
from typing import Any

from rerun.chunk import Chunk, RrdReader

from tests.remote.cutter import cutter
from tests.remote.helpers import (
    Server,
    link,
    operator,
    read_log,
    robot_log,
    run_dial,
    run_operator,
    server,
    wait_for,
)

PERTURBED = ("--perturb", "10", "--seed", "3")
BLOCK = ("--split", "block")


def _parallel(*jobs: Callable[[], Any]) -> list[Any]:
    with ThreadPoolExecutor(len(jobs)) as pool:
        futures = [pool.submit(job) for job in jobs]
        return [f.result(timeout=300) for f in futures]


def _through_link(tmp: Path, script: str, split: str) -> tuple[Any, ...]:
    """One run through a 1 s link, and the robot's log. Split block idles a round trip at
    each decision, in paced time: its pace is slower, so that it simulates fewer idle
    periods. Pour's split script robot is perturbed, to compare it with a local run."""
    args = PERTURBED if (script, split) == ("pour.dial", "script") else ()
    with server(tmp, *args, pace=0.1 if split == "script" else 0.25) as srv:
        code, summary, err = run_operator(
            srv, script, "--split", split, "--link", "delay=1s jitter=100ms", "--no-predict"
        )
        return code, summary, err, robot_log(srv.records())


def _local(tmp: Path, script: str, *args: str) -> list[dict[str, object]]:
    log = tmp / "local.jsonl"
    done = run_dial("run", script, "--quiet", "--log", str(log), *args)
    assert done.returncode == 0, done.stderr
    return [{k: v for k, v in r.items() if k != "wall_time"} for r in read_log(log)]


def test_both_splits_work_through_a_delayed_link_and_split_script_is_a_local_run(
    tmp_path: Path,
) -> None:
    """pour and the light bulb, split script and split block, through 'delay=1s
    jitter=100ms', on four servers at once; pour's split script robot (perturbed) logs
    what a local run with the same seed and perturbation logs."""
    cases = [(s, split) for s in ("pour.dial", "lightbulb.dial") for split in ("script", "block")]
    runs = _parallel(
        *(lambda c=c: _through_link(tmp_path / f"{c[0]}-{c[1]}", *c) for c in cases),
        lambda: _local(tmp_path, "pour.dial", *PERTURBED),
    )
    for (script, split), (code, summary, err, _) in zip(cases, runs, strict=False):
        assert code == 0, f"{script} --split {split}: {err}"
        assert summary is not None and summary["ok"] is True
        remote = summary["remote"]
        assert isinstance(remote, dict)  # (a late block is sent again: it still succeeds)
        assert isinstance(remote["rtt"], float) and remote["rtt"] >= 1.8  # two delays of 1 s
        assert remote["sent_bytes"] > 1000 and remote["received_bytes"] > remote["sent_bytes"]
        # Paced: never ahead of the wall clock times --pace (unpaced: 10-27x real time).
        pace = 0.1 if split == "script" else 0.25
        assert float(summary["robot_wall_time"]) >= 0.95 * pace * float(summary["sim_time"])
    assert runs[0][3] == runs[-1]  # split script: the robot's log is the local run's


def _twice(tmp: Path, *how: tuple[str, ...], external: str | None = None) -> list[Any]:
    """Runs of reactions.dial with --split block and no --lead, one per ``how``, on one
    server (the scene is reset between sessions); through ``dial link SPEC`` if given."""
    with ExitStack() as stack:
        srv = stack.enter_context(server(tmp, pace=0.2))
        url = None if external is None else stack.enter_context(link(srv.url, external))
        out = []
        for n, args in enumerate(how, start=1):  # (one 'dial link' serves both runs)
            log = tmp / f"op{n}.jsonl"
            code, summary, err = run_operator(srv, "reactions.dial", *args, log=log, url=url)
            assert code == 0, err
            assert summary is not None and summary["ok"] is True
            out.append((summary, robot_log(srv.records(), n), read_log(log), err))
        return out


def test_split_block_is_deterministic_without_lead_and_is_recorded(tmp_path: Path) -> None:
    """Two runs with --split block and no --lead through a jittered link give the same
    robot log: through --link (the lead comes from its spec), and through a 'dial link'
    process (the lead is the measured round trip rounded up to 0.5, 1, 2... s). The first
    run also predicts and records (--record: both robots, both sets of lanes)."""
    rrd = tmp_path / "run.rrd"
    block = ("--split", "block")
    jitter = "delay=0.1s jitter=50ms seed={}"
    spec, measured = _parallel(
        lambda: _twice(
            tmp_path / "spec",
            (*block, "--link", jitter.format(1), "--record", str(rrd)),
            (*block, "--link", jitter.format(2), "--no-predict", "--quiet"),
        ),
        lambda: _twice(tmp_path / "measured", block, block, external="jitter=30ms seed=3"),
    )
    for first, second in (spec, measured):
        assert first[1] == second[1]
        kinds = [r["kind"] for r in first[1]]
        assert kinds.count("block") == 3 and "monitor" in kinds and "idle" in kinds
    leads = [next(r for r in run[2] if r["kind"] == "lead") for run in (*spec, *measured)]
    assert [lead["source"] for lead in leads[:2]] == ["from the --link spec"] * 2
    assert leads[0]["seconds"] == 0.65  # 1.5 worst round trips (0.3 s) and 0.2 s
    assert all(str(lead["source"]).startswith("from the round trip") for lead in leads[2:])
    assert leads[2]["seconds"] == leads[3]["seconds"] == 0.5  # the grid's first step
    assert "'--lead 0.65' gives it again" in spec[0][3]  # said, so that it can be pinned
    assert "lead" not in spec[1][3]  # --quiet
    assert spec[0][0]["remote"]["diverged"] == 0  # predicted, undisturbed: no divergence
    _recorded(rrd, spec[0][2])


def _chunks(path: Path) -> list[Chunk]:
    return list(RrdReader(path).stream().collect().stream())


def _rows(chunks: list[Chunk], path: str, column: str) -> list[Any]:
    """Every non-static value of ``column`` at ``path``, in time order."""
    rows: list[tuple[Any, Any]] = []
    for c in chunks:
        batch = c.to_record_batch()
        if c.entity_path == path and not c.is_static and column in batch.schema.names:
            times = batch.column("sim_time").to_pylist()
            rows += zip(times, batch.column(column).to_pylist(), strict=True)
    return [value for _, value in sorted(rows, key=lambda r: r[0])]


def _recorded(rrd: Path, op: list[dict[str, object]]) -> None:
    """The recording reads back whole, with the predicted robot and the reported one, each
    moving, and both sets of lanes, the reported ones as the robot reported them."""
    reader = RrdReader(rrd)
    assert len(reader.recordings()) == 1
    chunks = _chunks(rrd)
    paths = {c.entity_path for c in chunks}
    for robot in ("/world", "/world/reported"):
        poses = _rows(chunks, f"{robot}/hand/index_distal", "Transform3D:translation")
        assert len(poses) > 10, robot
        assert max(abs(a - b) for a, b in zip(poses[0][0], poses[-1][0], strict=True)) > 0.01
    assert "/world/reported/arm/link2/capsule" in paths  # the geometry, drawn again
    assert "/world/reported/bulb" not in paths and "/world/bulb" not in paths  # robots only
    for lanes in ("", "/reported"):
        assert {f"{lanes}/01_reach", f"{lanes}/04_touch"} <= paths
    states = [s for s in _rows(chunks, "/reported/03_down", "StateChange:state") if s]
    ended = [r for r in op if r["kind"] == "end" and r["event"] == "down"]
    assert ["running"] in states and [str(ended[0]["outcome"])] in states


def _into_block(srv: Server, ticks: int) -> bool:
    """The robot has run ``ticks`` ticks of its first block (and not yet finished it)."""
    kinds = [(r["kind"], r.get("tick")) for r in srv.records()]
    begun = [tick for kind, tick in kinds if kind == "block"]
    ended = any(kind in ("condition", "idle") for kind, _ in kinds)
    return bool(begun) and not ended and ("tick", int(str(begun[0])) + ticks) in kinds


def test_a_cut_in_a_block_is_followed_by_a_reconnect_and_each_block_runs_once(
    tmp_path: Path,
) -> None:
    """The link drops for 3 s while pour's first block (13 ticks) runs at the robot, with
    --split block (through a relay that the test cuts 4 ticks into the block; watchdog
    6 s): the block runs on, the operator reconnects and sends again what was not
    acknowledged, the robot runs each command and each block once, and the run succeeds
    (through the link emulation's own cut, too: --link "delay=0.05s cut=...")."""
    log = tmp_path / "op.jsonl"
    with (
        server(tmp_path, "--watchdog", "6", pace=0.3) as srv,
        cutter(srv.url) as relay,
        operator(srv, "pour.dial", *BLOCK, "--no-predict", log=log, url=relay.url) as op,
    ):
        assert wait_for(lambda: _into_block(srv, 4), 90), srv.records()[-3:]
        relay.cut(3.0)
        out, err = op.communicate(timeout=150)
        records = srv.records()
    assert op.returncode == 0, err
    summary = json.loads(out.strip().splitlines()[-1])
    assert summary["ok"] is True
    kinds = [r["kind"] for r in records]
    cut, back = kinds.index("disconnected"), kinds.index("session", 1)
    assert records[back]["resumed"] is True  # a reconnect to the same session
    assert 3.0 <= float(records[back]["wall"]) - float(records[cut]["wall"]) < 6.0
    # The cut came in the middle of block 1, which ran on through it at the robot.
    assert kinds[:cut].count("block") == 1 and "condition" not in kinds[:cut]
    assert "tick" in kinds[cut : kinds.index("condition")]
    received = [r["seq"] for r in records if r["kind"] == "received"]
    assert len(received) == len(set(received))  # no command received twice
    blocks = [(r["number"], r["line"]) for r in robot_log(records) if r["kind"] == "block"]
    assert [n for n, _ in blocks] == list(range(1, len(blocks) + 1))  # each block once
    assert blocks[0][1] == 75 and [line for _, line in blocks].count(75) == 1
    ticks = [r["tick"] for r in read_log(log) if r["kind"] == "tick"]
    assert ticks == sorted(set(ticks))  # every record reported once, in order


def test_a_push_at_the_robot_diverges_from_the_prediction(tmp_path: Path) -> None:
    """A push at the robot gives a 'diverged' record within one telemetry period of the
    push being reported, and the recording's log says so; an undisturbed run gives none
    (the first run of the test above)."""
    push = "push body=hand_base force=0,300,0 at=0.5 for=0.3"
    rrd = tmp_path / "push.rrd"
    with server(tmp_path, "--disturb", push, pace=0.5) as srv:
        run_operator(srv, "reactions.dial", "--record", str(rrd), log=tmp_path / "op.jsonl")
    op = read_log(tmp_path / "op.jsonl")
    begin = next(r for r in op if r["kind"] == "disturb" and r["phase"] == "begin")
    tool = [r for r in op if r["kind"] == "diverged" and r["what"] == "tool"]
    assert tool, "no diverged record"
    # The first sample after the push reported leaves the prediction: within one
    # telemetry period (0.1 s of simulated time).
    assert float(begin["t"]) < float(tool[0]["t"]) <= float(begin["t"]) + 0.1 + 1e-6
    assert tool[0]["tick"] == begin["tick"] and tool[0]["event"]
    text = [str(t[0]) for t in _rows(_chunks(rrd), "/events/log", "TextLog:text")]
    assert any(line.startswith(f"diverged at tick {begin['tick']}") for line in text)
