"""The tools on the second robot (allegro_panda): `dial preview` of a bundled script with only
the scene changed, a scripted `dial teach` session whose names a script then runs with, and a
`--record` recording with the robot's own joints, loads and pads."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rerun.chunk import Chunk, RrdReader

from dial.cli import main
from dial.scene import load_world

from ..conftest import ROOT

TOUCH = ROOT / "tests" / "robots" / "allegro_touch.dial"
FINGERS = ("index", "middle", "ring", "thumb")


def _dial(*args: str, stdin: str = "") -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run(
        [sys.executable, "-m", "dial.cli", *args],
        input=stdin,
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )


def test_preview_of_a_bundled_script_on_the_second_robot(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["preview", "lightbulb.dial", "--scene", "allegro_panda/lightbulb"]) == 0
    out = capsys.readouterr().out
    assert "lightbulb.dial: preview OK: 14 blocks, 15 arm targets" in out, out


SESSION = """\
pose trace_point
ex to_south
jog world 0 0 5
finger index 0 -5 -5 -5
drive 7 2
save pose flat_index
save location above relative-to block
write
"""

SCRIPT = """\
@scene {world}
@tick 0.25
% pose hand_pose "flat_index"
% go puma_command "move above"
pose #===
go       #======
"""


def test_a_taught_pose_and_location_on_the_second_robot(tmp_path: Path) -> None:
    taught = tmp_path / "taught.toml"
    done = _dial("teach", "--scene", "allegro_panda/surface", "--into", str(taught), stdin=SESSION)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "index   abd   -0.6  mcp   -5.0  pip   -5.0  dip   -5.1  deg" in done.stdout
    world = load_world(taught)
    assert world.robot == (ROOT / "models" / "allegro_panda").resolve()
    above = world.locations["above"]
    # 5 mm above trace_south (the pad 15 mm above the block's top), in the block's frame.
    assert above.body == "surface_block"
    assert above.pos == pytest.approx((-0.0446, -0.208, 0.0082), abs=3e-4)
    pose = world.poses["flat_index"].angles
    assert [round(np.degrees(pose[bit])) for bit in range(4)] == [0, -5, -5, -5]
    script = tmp_path / "taught.dial"
    script.write_text(SCRIPT.format(world=taught))
    log = tmp_path / "run.jsonl"
    ran = _dial("run", str(script), "--quiet", "--json", "--log", str(log))
    summary = json.loads(ran.stdout.splitlines()[-1])  # the surface's criterion: no plane here
    assert summary["error"] is None and summary["success"] == {"top_plane": False}, summary
    records = [json.loads(line) for line in log.read_text().splitlines()]
    assert [r["outcome"] for r in records if r["kind"] == "end"] == ["done", "done"]


def _rows(chunks: list[Chunk], path: str) -> list[Any]:
    rows: list[tuple[Any, Any]] = []
    for c in chunks:
        batch = c.to_record_batch()
        if c.entity_path == path and not c.is_static and "Scalars:scalars" in batch.schema.names:
            column = batch.column("Scalars:scalars").to_pylist()
            rows += zip(batch.column("sim_time").to_pylist(), column, strict=True)
    return [value for _, value in sorted(rows, key=lambda r: r[0])]


def test_a_recording_of_the_second_robot(tmp_path: Path) -> None:
    rrd = tmp_path / "run.rrd"
    assert main(["run", str(TOUCH), "--record", str(rrd), "--quiet"]) == 1  # no plane fitted
    chunks = list(RrdReader(rrd).stream().collect().stream())
    arm = _rows(chunks, "/robot/arm")
    assert arm and all(len(row) == 7 for row in arm)  # the Panda's seven joints
    for f in FINGERS:
        joints, loads = _rows(chunks, f"/robot/hand/{f}"), _rows(chunks, f"/robot/tendons/{f}")
        assert len(joints) == len(loads) == len(arm)
        assert all(len(row) == 4 for row in joints + loads)  # one torque per joint
    paths = {c.entity_path for c in chunks}
    robot = {"/world/hand/index_distal", "/world/hand/base", "/world/arm/link7"}
    assert robot | {"/tactile/thumb", "/01_pose", "/03_press"} <= paths
