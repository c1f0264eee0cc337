"""``dial teach`` and ``dial world``: what the command line calls."""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any, TextIO

from dial.errors import DialError
from dial.scene.resolve import resolve_scene
from dial.scene.world import load_world
from dial.teach.describe import describe
from dial.teach.repl import Hook, interactive, scripted
from dial.teach.session import Session
from dial.teach.sim import CONTROL_PERIOD, Sim
from dial.teach.target import open_target

VIEWER_EVERY = 2  # control periods between viewer updates (50 Hz)


def teach(
    scene: str,
    into: str | None,
    snapshot: Path | None = None,
    viewer: bool = False,
    stdin: TextIO | None = None,
    out: TextIO | None = None,
) -> int:
    """Run a teaching session; 0 when it ends with nothing left unwritten."""
    stdin, out = stdin or sys.stdin, out or sys.stdout
    world, target = open_target(scene, into, Path.cwd())
    sim = Sim(world)
    session = Session(world, target, sim)
    action = "writes" if target.exists else "creates"
    print(f"scene {scene}: 'write' {action} {target.path}", file=out)
    closers: list[Any] = []
    after: Hook | None = None
    try:
        if snapshot is not None:
            from dial.teach.pictures import Snapshots

            shots = Snapshots(sim, snapshot)
            closers.append(shots)
            shots("start")
            after = shots
        if viewer:
            closers.append(_attach_viewer(sim))
        if stdin.isatty():
            return interactive(session, after)
        return scripted(session, stdin, out, after)
    finally:
        for closer in closers:
            closer.close()


def _attach_viewer(sim: Sim) -> Any:
    """MuJoCo's passive viewer, updated as the session steps, paced to wall-clock time."""
    from dial.engine.observe import first_line
    from dial.recording.viewer import _probe_glfw

    _probe_glfw()
    import mujoco.viewer

    try:
        handle = mujoco.viewer.launch_passive(sim.model, sim.data)
    except Exception as e:  # GLFW and GL failures come as assorted errors
        raise DialError(f"--viewer could not open MuJoCo's viewer: {first_line(e)}") from e
    count = 0

    def update() -> None:
        nonlocal count
        count += 1
        if count % VIEWER_EVERY == 0 and handle.is_running():
            handle.sync()
            time.sleep(VIEWER_EVERY * CONTROL_PERIOD)  # pacing only: results do not change

    sim.on_period = update
    return handle


def world(scene: str, picture: Path | None = None) -> tuple[str, int]:
    """``dial world S [--picture F.png]``: the scene's names as aligned text, and how many
    location frames the picture shows (0 without one)."""
    world = load_world(resolve_scene(scene, Path.cwd()))
    sim = Sim(world, settle=False)  # the objects where the world model believes them
    drawn = 0
    if picture is not None:
        from dial.teach.pictures import world_picture

        drawn = world_picture(sim, picture)
    return describe(world, sim.ctx.believed, sim.ctx.world_model.sizes), drawn
