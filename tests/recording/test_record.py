"""--record: the recording read back with rerun's own API; watching a run changes nothing."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rerun.chunk import Chunk, RrdReader

from dial.backend.model import FINGERS
from dial.cli import main
from dial.engine import RunOptions, StateLog, run
from dial.parser import load
from dial.recording.frames import RECORD_HZ, Batch
from dial.recording.observers import Recorder
from dial.recording.rerun_sink import GUARD_SHOWN_S, SOLID, RerunSink
from dial.scene import load_scene_names
from tests.recording.conftest import without_wall_time


def _chunks(path: Path) -> list[Chunk]:
    return list(RrdReader(path).stream().collect().stream())


def _column(chunk: Chunk, name: str) -> list[Any]:
    return list(chunk.to_record_batch().column(name).to_pylist())


def _rows(chunks: list[Chunk], path: str, column: str) -> list[Any]:
    """Every non-static value of ``column`` at ``path``, in time order."""
    rows: list[tuple[Any, Any]] = []
    for c in chunks:
        has = column in c.to_record_batch().schema.names
        if c.entity_path == path and not c.is_static and has:
            rows += zip(_column(c, "sim_time"), _column(c, column), strict=True)
    return [value for _, value in sorted(rows, key=lambda r: r[0])]


def _static(chunks: list[Chunk], path: str) -> set[str]:
    """The component columns logged statically at ``path``."""
    names: set[str] = set()
    for c in chunks:
        if c.entity_path == path and c.is_static:
            names |= set(c.to_record_batch().schema.names)
    return names


def test_record_holds_the_run_and_leaves_the_log_unchanged(
    short_script: Path, tmp_path: Path
) -> None:
    plain, recorded, rrd = tmp_path / "plain.jsonl", tmp_path / "rec.jsonl", tmp_path / "run.rrd"
    status = main(["run", str(short_script), "--log", str(plain), "--quiet"])
    assert (
        main(["run", str(short_script), "--log", str(recorded), "--record", str(rrd), "--quiet"])
        == status
    )
    assert without_wall_time(recorded) == without_wall_time(plain)

    reader = RrdReader(rrd)
    assert len(reader.recordings()) == 1 and len(reader.blueprints()) == 1
    chunks = _chunks(rrd)
    paths = {c.entity_path for c in chunks}
    expected = {"/world", "/world/block", "/world/arm/link2", "/world/hand/index_distal"}
    expected |= {f"/robot/{kind}/{f}" for kind in ("hand", "tendons") for f in FINGERS}
    expected |= {f"/tactile/{f}" for f in FINGERS} | {"/robot/arm", "/events/log"}
    expected |= {"/01_to", "/02_open", "/03_grab", "/04_down", "/05_forces"}  # script order
    assert expected <= paths

    # Geometry, once and static, every shape solid: the block is a box, finger links capsules.
    def drawn(body: str, column: str) -> bool:
        return any(p.startswith(f"{body}/") and column in _static(chunks, p) for p in paths)

    assert drawn("/world/block", "Boxes3D:half_sizes")
    assert drawn("/world/hand/index_distal", "Capsules3D:radii")
    assert "/world/hand/index_distal/capsule" in paths  # unnamed geoms are named by kind
    for c in chunks:
        if c.is_static and "Capsules3D:radii" in c.to_record_batch().schema.names:
            assert _column(c, "Capsules3D:fill_mode") == [[SOLID.value]], c.entity_path

    # Both timelines, and only they, on everything that changes.
    for c in chunks:
        if not c.is_static and c.entity_path != "/__properties":
            assert set(c.timeline_names) == {"sim_time", "tick"}, c.entity_path

    # Frames at RECORD_HZ of simulated time, from the start to the end of the run.
    sim_time = json.loads(plain.read_text().splitlines()[-1])["sim_time"]
    joints = _rows(chunks, "/robot/hand/index", "Scalars:scalars")
    assert len(joints) == round(sim_time / 0.01) // round(100 / RECORD_HZ) + 1
    assert all(len(row) == 4 for row in joints)
    tendons = _rows(chunks, "/robot/tendons/thumb", "Scalars:scalars")
    assert len(tendons) == len(joints) and all(len(r) == 8 for r in tendons)
    poses = _rows(chunks, "/world/hand/index_distal", "Transform3D:translation")
    assert len(poses) == len(joints)
    assert np.ptp(np.array(poses, dtype=float), axis=0).max() > 0.01  # the hand moved

    arm = _rows(chunks, "/robot/arm", "Scalars:scalars")
    assert len(arm) == len(joints) and all(len(row) == 6 for row in arm)

    # Tactile images: 16x16 float depths (mm) with a colormap.
    for f in FINGERS:
        static = [c for c in chunks if c.entity_path == f"/tactile/{f}" and c.is_static]
        (image,) = [c for c in static if "DepthImage:format" in c.to_record_batch().schema.names]
        (fmt,) = _column(image, "DepthImage:format")
        assert isinstance(fmt, list) and (fmt[0]["width"], fmt[0]["height"]) == (16, 16)
        assert "DepthImage:colormap" in _static(chunks, f"/tactile/{f}")
        buffers = _rows(chunks, f"/tactile/{f}", "DepthImage:buffer")
        assert len(buffers) == len(joints)
        assert all(np.frombuffer(bytes(b[0]), np.float32).shape == (256,) for b in buffers)

    # Event lanes: every event's lane is there from time 0, empty (so that an event that
    # never runs has its lane too); then running from a start, the outcome over the same
    # span, then held.
    for name in ("/01_to", "/02_open", "/03_grab", "/04_down", "/05_forces"):
        assert _rows(chunks, name, "StateChange:state")[0] == [], name
    lane = _rows(chunks, "/02_open", "StateChange:state")
    assert lane[1:4] == [["running"], ["done"], ["held"]] and lane[-1] in ([], [""])  # ends it
    text = [t[0] for t in _rows(chunks, "/events/log", "TextLog:text")]
    assert "start to (line 9)" in text and any(t.startswith("end   grab done") for t in text)
    assert any(t.startswith(("OK", "FAILED")) for t in text)  # the criteria, at the end


def test_observers_leave_the_physics_alone(short_script: Path, tmp_path: Path) -> None:
    script = load(short_script, loader=load_scene_names)
    bare = run(script, RunOptions())
    sink = RerunSink(tmp_path / "run.rrd")
    watched = run(script, RunOptions(observers=[StateLog(), Recorder(sink, "short")]))
    assert watched.final_qpos == bare.final_qpos

    def timeless(records: list[dict[str, object]]) -> list[dict[str, object]]:
        return [{k: v for k, v in r.items() if k != "wall_time"} for r in records]

    records = [r for r in watched.log.records if r["kind"] != "state"]
    assert timeless(records) == timeless(bare.log.records)


def test_tactile_images_show_the_fingertip_up(tmp_path: Path) -> None:
    n = 2
    tactile = np.zeros((n, 4, 16, 16))
    tactile[:, 3, 15, 0] = 5e-4  # thumb: distal row, -x column
    batch = Batch(
        time_ns=np.array([0, 20_000_000]),
        tick=np.array([0, 1]),
        pos=np.zeros((n, 0, 3)),
        quat=np.zeros((n, 0, 4)),
        joints=np.zeros((n, 16)),
        arm=np.zeros((n, 6)),
        tensions=np.zeros((n, 32)),
        tactile=tactile,
        task=np.zeros((n, 0)),
    )
    sink = RerunSink(tmp_path / "tactile.rrd")
    sink.frames(batch)
    sink.close()
    (first, _) = _rows(_chunks(tmp_path / "tactile.rrd"), "/tactile/thumb", "DepthImage:buffer")
    image = np.frombuffer(bytes(first[0]), np.float32).reshape(16, 16)
    assert image[0, 0] == np.float32(0.5) and np.count_nonzero(image) == 1  # top left, in mm


def test_contact_points_and_fits_are_drawn(tmp_path: Path) -> None:
    sink = RerunSink(tmp_path / "fits.rrd")
    tips = np.arange(12, dtype=float).reshape(4, 3)
    plane = {
        "set": "top",
        "normal": [0.0, 0.0, 1.0],
        "axes": [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        "extents": [0.1, 0.05],
        "centroid": [0.5, 0.0, 0.45],
    }
    quadric = {
        "set": "solid",
        "size": [0.03, 0.02, 0.05],
        "shape": [0.5, 1.0],
        "centre": [0.5, 0.2, 0.45],
        "rotation": np.eye(3).tolist(),
    }
    records: list[dict[str, object]] = [
        {"kind": "end", "event": "rc", "line": 3, "tick": 2, "t": 0.2, "outcome": "done",
         "data": {"point": [0.5, 0.0, 0.45], "set": "top", "count": 1}},
        {"kind": "contact", "effector": "arm", "sensor": "tactile", "finger": "ring",
         "value": 0.001, "t": 0.25, "step": 125},
        {"kind": "end", "event": "fp", "line": 4, "tick": 3, "t": 0.3, "outcome": "done",
         "data": plane},
        {"kind": "end", "event": "fs", "line": 5, "tick": 3, "t": 0.3, "outcome": "done",
         "data": quadric},
    ]  # fmt: skip
    for record in records:
        sink.record(record, 3, tips)
    sink.close()
    chunks = _chunks(tmp_path / "fits.rrd")
    guards = _rows(chunks, "/world/contacts/guards/01", "Points3D:positions")
    assert np.allclose(guards, [[tips[2]]])  # the ring fingertip
    label = _rows(chunks, "/world/contacts/guards/01", "Points3D:labels")
    assert label == [["ring tactile 0.001 m"]]
    cleared = [c for c in chunks if c.entity_path == "/world/contacts/guards/01"]
    cleared = [c for c in cleared if "Clear:is_recursive" in c.to_record_batch().schema.names]
    (when,) = _column(cleared[0], "sim_time")
    assert when.total_seconds() == pytest.approx(0.25 + GUARD_SHOWN_S)  # then it is gone
    assert np.allclose(
        _rows(chunks, "/world/contacts/top", "Points3D:positions"), [[[0.5, 0, 0.45]]]
    )
    box = _rows(chunks, "/world/fits/top", "Boxes3D:half_sizes")
    assert np.allclose(box, [[[0.05, 0.025, 0.0005]]])
    mesh = _rows(chunks, "/world/fits/solid", "Mesh3D:vertex_positions")[0]
    assert np.allclose(np.ptp(np.array(mesh), axis=0), [0.06, 0.04, 0.1])


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--record", "run.jsonl"], "--record writes a .rrd file, not 'run.jsonl'"),
        (["--log-states"], "--log-states writes into the log: give --log FILE.jsonl too"),
    ],
)
def test_usage_errors_exit_2_before_the_run(
    short_script: Path, argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["run", str(short_script), *argv]) == 2
    assert capsys.readouterr().err == f"dial: {message}\n"


def test_an_unwritable_recording_is_one_line_and_exit_1(
    short_script: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rrd = tmp_path / "missing" / "run.rrd"
    assert main(["run", str(short_script), "--record", str(rrd)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("dial: cannot write the recording: ") and err.count("\n") == 1
