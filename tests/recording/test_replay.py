"""dial replay: the timeline from a log, and a recording rebuilt from its states."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from rerun.chunk import RrdReader

from dial.cli import main
from dial.engine.observe import STATE_HZ
from dial.recording.timeline import describe, timeline, when
from tests.recording.conftest import without_wall_time


def _rounded(value: object) -> object:
    """Floats to 0.1 mm: a replay's scene comes from positions logged to that precision."""
    if isinstance(value, float):
        return round(value, 4) + 0.0
    if isinstance(value, list):
        return [_rounded(v) for v in value]
    return value


def _blueprint(rrd: Path) -> list[tuple[str, str]]:
    """The layout in a recording: every blueprint entity and component, without their ids."""
    reader = RrdReader(rrd)
    (store,) = reader.blueprints()
    rows = []
    for c in reader.stream(store=store).collect().stream():
        batch = c.to_record_batch()
        for name, column in zip(batch.schema.names, batch.columns, strict=True):
            ids = ("contents", "root_container", "active_tab")  # random ids of the containers
            if not name.startswith(("Container", "View", "TimePanel", "Spatial", "Eye")):
                continue
            if any(i in name for i in ids):
                continue
            rows.append((name, json.dumps(_rounded(column.to_pylist()), default=str)))
    return sorted(rows)


def test_replay_prints_the_timeline_and_rebuilds_a_recording(
    short_script: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log, rrd, live = tmp_path / "run.jsonl", tmp_path / "replay.rrd", tmp_path / "live.rrd"
    main(["run", str(short_script), "--log", str(log), "--log-states", "--record", str(live)])
    records = [json.loads(line) for line in log.read_text().splitlines()]
    assert records[1]["kind"] == "lanes"  # the script's lanes, for the replay
    states = [r for r in records if r["kind"] == "state"]
    summary = records[-1]
    periods = round(summary["sim_time"] / 0.01)
    assert len(states) == periods // round(100 / STATE_HZ) + 1  # at t = 0, then every 40 ms
    assert states[1]["t"] == pytest.approx(1 / STATE_HZ)
    assert len(states[0]["qpos"]) == 29 and len(states[0]["tension"]) == 32  # surface scene

    capsys.readouterr()
    assert main(["replay", str(log), "--record", str(rrd)]) == 0
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert lines[0].split() == ["tick", "t", "(s)", "what"]
    assert lines[1].endswith("scene surface (surface.toml), seed 0, objects perturbed 0.0 mm")
    assert "    1     0.000  start to (line 9)" in lines
    assert any(" end   grab done" in line for line in lines)
    assert lines[-1].split()[2] in ("OK", "FAILED")
    assert err == f"{rrd}: {len(states)} frames rebuilt from {log}\n"

    chunks = list(RrdReader(rrd).stream().collect().stream())
    paths = {c.entity_path for c in chunks}
    assert {"/world/block", "/tactile/thumb", "/03_grab", "/robot/arm"} <= paths
    rows = sum(c.num_rows for c in chunks if c.entity_path == "/world/hand/base")
    assert rows == len(states)

    # The same layout and the same lanes as the live recording, holds included.
    live_chunks = list(RrdReader(live).stream().collect().stream())
    assert _blueprint(rrd) == _blueprint(live)
    assert {p for p in paths if p[1:3].isdigit()} == {
        c.entity_path for c in live_chunks if c.entity_path[1:3].isdigit()
    }
    lane = [
        state
        for c in chunks
        if c.entity_path == "/02_open" and "StateChange:state" in c.to_record_batch().schema.names
        for state in c.to_record_batch().column("StateChange:state").to_pylist()
    ]
    assert ["held"] in lane


def test_replay_without_states_says_how_to_get_them(
    short_script: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = tmp_path / "run.jsonl"
    main(["run", str(short_script), "--log", str(log), "--quiet"])
    assert main(["replay", str(log)]) == 0
    capsys.readouterr()
    assert main(["replay", str(log), "--record", str(tmp_path / "x.rrd")]) == 1
    err = capsys.readouterr().err
    assert "no 'state' records" in err and "--log-states" in err
    assert without_wall_time(log)  # the log is untouched and still well formed


def test_replay_rejects_what_is_not_a_log(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.jsonl"
    bad.write_text('{"kind":"start"}\n')
    assert main(["replay", str(bad)]) == 1
    assert "not a dial run log" in capsys.readouterr().err
    assert main(["replay", str(tmp_path / "missing.jsonl")]) == 1


def test_a_torn_last_line_is_dropped(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = tmp_path / "torn.jsonl"
    log.write_text('{"kind":"scene","scene":"pour","world":"pour.toml","seed":0}\n{"kind":"st')
    assert main(["replay", str(log)]) == 0
    assert "scene pour" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("record", "text", "level"),
    [
        ({"kind": "end", "event": "g", "outcome": "missed", "message": "no"},
         "end   g missed: no", "warn"),
        ({"kind": "end", "event": "g", "outcome": "timeout"}, "end   g timeout", "error"),
        ({"kind": "tick", "tick": 3, "stretch": 5},
         "tick 3 stretched by 5 control periods", "info"),
        ({"kind": "condition", "condition": "!g", "value": True}, "condition !g is true", "info"),
        ({"kind": "condition", "condition": "g", "value": False, "script": "a/sub.dial"},
         "condition g is false (in sub.dial)", "info"),
        ({"kind": "start", "event": "g", "line": 4, "script": "a/sub.dial"},
         "start sub.g (line 4)", "info"),
        ({"kind": "contact", "sensor": "force", "finger": "ring", "effector": "arm", "value": 2.5},
         "contact: force on the ring stopped the arm (2.5)", "info"),
        ({"kind": "warning", "message": "tendon held"}, "tendon held", "warn"),
        ({"kind": "summary", "ok": False, "success": {"a": False}, "criteria": {"a": "far"}},
         "FAILED [ ] a: far", "error"),
    ],
)  # fmt: skip
def test_describe(record: dict[str, object], text: str, level: str) -> None:
    assert describe(record) == (text, level)


def test_bookkeeping_records_are_not_described() -> None:
    assert describe({"kind": "tick", "tick": 3, "stretch": 0}) is None
    assert describe({"kind": "state", "t": 0.0, "tick": 0, "qpos": []}) is None
    assert timeline([{"kind": "state", "t": 0.0, "tick": 0}]).count("\n") == 1


def test_a_summary_holds_a_tick_length_not_a_tick() -> None:
    assert when({"kind": "summary", "sim_time": 2.5, "tick": 0.25}, 7) == (2.5, 7)
    assert when({"kind": "tick", "tick": 3, "t0": 0.2, "t1": 0.3}, 2) == (0.3, 3)


def test_replay_video_needs_a_known_format(
    short_script: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("imageio", reason="the 'video' extra is not installed")
    log = tmp_path / "run.jsonl"
    log.write_text('{"kind":"scene","scene":"surface"}\n')
    assert main(["replay", str(log), "--video", str(tmp_path / "run.avi")]) == 2
    assert "--video writes .mp4 or .gif files, not '.avi'" in capsys.readouterr().err
    assert main(["replay", str(log), "--video", str(tmp_path / "run.gif")]) == 1
    assert "no 'state' records to rebuild a video from" in capsys.readouterr().err
