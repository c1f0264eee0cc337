"""The robot's side of a session, in a thread of its own: check, run, report, hold.

The robot holds the simulated robot in its *true* world (``dial serve --perturb --seed
--disturb``) and runs, paced to the wall clock times ``--pace``, either the whole checked
script (``--split script``, through the engine as ``dial run`` does) or the blocks its
operator sends (``--split block``, :mod:`dial.remote.blocks`). Its log records, results and
telemetry go through the :class:`~dial.remote.session.Session`. Whatever ends the run, every
effector then holds, and the physics goes on with the effectors held for ``HOLD_S`` of wall
time (then the simulation parks), or until the next session resets the scene.
"""

from __future__ import annotations

import posixpath
import tempfile
import time
from collections.abc import Mapping
from pathlib import Path

from dial.engine.result import RunResult
from dial.errors import DialError, ScriptError
from dial.parser.check import load as check_file
from dial.parser.script import Script
from dial.remote.blocks import run_blocks
from dial.remote.protocol import Message
from dial.remote.session import Session, Tee
from dial.remote.telemetry import RobotConfig, Telemetry, disturbances
from dial.scene import load_scene_names
from dial.scene.resolve import scene_option

HOLD_S = 5.0  # wall s the held robot is simulated after a run ends; then it parks
SAMPLE_BYTES = 420  # about the size of one telemetry message
TELEMETRY_EVERY = 10  # control periods between samples at most (0.1 s of simulated time)
MAX_FILES = 64


def checked_upload(upload: Mapping[str, object], scene: str | None, folder: Path) -> Script:
    """The uploaded script, written into ``folder`` and checked against the robot's own
    world (``scene``, else the script's ``@scene``): a :class:`ScriptError` or a one-line
    :class:`DialError` if it does not fit."""
    path, main, files = upload.get("path"), upload.get("main"), upload.get("files")
    if not (isinstance(path, str) and isinstance(main, str) and isinstance(files, dict)):
        raise DialError("the script upload needs 'path', 'main' and 'files' (docs/remote.md)")
    if main not in files or len(files) > MAX_FILES:
        raise DialError(f"the upload must hold its main file '{main}' and at most {MAX_FILES}")
    for name, text in files.items():
        clean = posixpath.normpath(name)
        if (
            not isinstance(text, str)
            or clean != name
            or name.startswith(("/", ".."))
            or not name.endswith(".dial")
        ):
            raise DialError(f"bad file in the upload: '{name}' (relative .dial paths only)")
        target = folder / clean
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")
    override = None if scene is None else scene_option(scene)
    return check_file(folder / main, scene=override, loader=load_scene_names, display=path)


def robot_main(session: Session, config: RobotConfig, first: Message, every: int) -> None:
    """The robot thread: check the upload, run it, report the end, hold."""
    seq, ident = first.integer("seq"), first.text("id")
    telemetry = Telemetry(session, every)
    try:
        with tempfile.TemporaryDirectory(prefix="dial-upload-") as folder:
            try:
                script = checked_upload(first.obj("script"), config.scene, Path(folder))
            except ScriptError as e:
                _reject(session, seq, ident, e.render())
                return
            except DialError as e:
                _reject(session, seq, ident, str(e))
                return
            if session.state == "ready":  # (not lost while it was being checked)
                session.state = "running"
            session.report("result", seq=seq, id=ident, tick=0, checked=True)
            result = _run(session, config, first, script, telemetry)
    except DialError as e:  # a scene that cannot be set up, a log that cannot be written
        session.state = "stopped"
        session.report("finished", summary={"ok": False, "error": str(e)})
        return
    if session.stop.signal == "link lost":
        session.state = "lost"
    elif session.stop.signal is not None:
        session.state = "stopped"
    else:
        session.state = "finished"
    session.report("finished", summary=result.as_record())
    hold(session, telemetry, config.pace)


def _reject(session: Session, seq: int, ident: str, message: str) -> None:
    session.state = "rejected"
    session.report("refused", seq=seq, id=ident, code="rejected", message=message)


def _run(
    session: Session, config: RobotConfig, first: Message, script: Script, telemetry: Telemetry
) -> RunResult:
    tick = first.number("tick_length")
    if first.type == "run":
        from dial.engine.run import RunOptions
        from dial.engine.run import run as run_engine

        options = RunOptions(
            tick=tick,
            seed=config.seed,
            perturb_mm=config.perturb,
            disturb=disturbances(config.disturb),
            log=Tee(session),
            observers=[telemetry],
            pace=config.pace,
            stop=session.stop,
        )
        return run_engine(script, options)
    return run_blocks(session, config, script, first, telemetry)


def hold(session: Session, telemetry: Telemetry, pace: float) -> None:
    """Simulate the held robot, paced, until the next session, or for HOLD_S of wall time."""
    robot = telemetry.robot
    if robot is None:
        return
    robot.hold_all()
    start, k = time.monotonic(), 0
    periods = round(robot.time / robot.period)
    while not session.closing.is_set() and time.monotonic() - start < HOLD_S:
        robot.advance()
        k += 1
        if (periods + k) % telemetry.every == 0:
            telemetry.sample(periods + k, session.tick)
        lag = start + k * robot.period * pace - time.monotonic()
        if lag > 0:
            session.closing.wait(lag)
