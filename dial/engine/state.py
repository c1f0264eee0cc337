"""State files: a run saved just before a block starts, to resume exactly (DESIGN 6.1).

A state file is JSON (docs/debugging.md documents every field), version 1. It holds the
physics (``mj_getState`` with ``mjSTATE_INTEGRATION``: time, positions, velocities,
actuation, warm start, controls, applied forces, active equalities), the driver's
set-points and limp joints, the safety monitor's timers, the position in the timeline (a
:data:`~dial.scheduler.position.Path`), the clocks, the latest outcomes and counts, the
recorded contact sets and fits, the options the run was made with (tick, seed,
perturbation, disturbances: dial draws random numbers only for ``--perturb``, from the
seed, at setup), and a fingerprint of every script line before the saved position.
Float arrays are base64 of little-endian float64, so a resumed run is bit-identical.
"""

from __future__ import annotations

import base64
import hashlib
import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from dial.backend.driver import MujocoRobot
from dial.disturb import Disturbance, parse_disturbance
from dial.errors import DialError
from dial.parser.script import Script, Step, TBlock, TCall, TIf, TRepeat, scripts_of
from dial.primitives.context import Context
from dial.robot.snapshot import Touch
from dial.scene.belief import Held
from dial.scheduler.position import Frame, Resume, TimelinePath
from dial.scheduler.primitive import Outcome
from dial.scheduler.ticks import TickLoop

FORMAT, VERSION = "dial-state", 1
PHYSICS = mujoco.mjtState.mjSTATE_INTEGRATION
# What dial reads of MjData between physics steps (snapshots, taxel points, poses). After a
# step these hold the step's forward pass, one integration behind the positions, which
# mj_forward on the restored state would not reproduce: they are saved as they were.
DERIVED = (
    "sensordata",
    "xpos",
    "xquat",
    "xmat",
    "geom_xpos",
    "geom_xmat",
    "site_xpos",
    "site_xmat",
)


class StateFileError(DialError):
    """A state file that cannot be resumed from: the message names the file and why."""


@dataclass(frozen=True)
class RunSettings:
    """The options a state belongs to: a resumed run uses these, not the command line's."""

    tick: float
    seed: int
    perturb_mm: float
    disturb: tuple[Disturbance, ...]


def _array(values: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(values, dtype="<f8").tobytes()).decode()


def _floats(text: str, n: int | None, what: str) -> np.ndarray:
    values = np.frombuffer(base64.b64decode(text.encode(), validate=True), dtype="<f8")
    if n is not None and values.size != n:
        raise ValueError(f"{what} has {values.size} numbers, not {n}")
    return values.astype(np.float64)


def _point(point: np.ndarray | None) -> str | None:
    """A stop's contact point, exact (base64 of the float64s), or None."""
    return None if point is None else _array(point)


def _stop_point(text: str | None) -> np.ndarray | None:
    return None if text is None else _floats(text, 3, "a stop's contact point")


def _flags(values: list[Any], n: int, what: str) -> np.ndarray:
    if not isinstance(values, list) or len(values) != n:
        raise ValueError(f"{what} has not {n} flags")
    return np.array(values, dtype=bool)


def _key(top: Script, path: str) -> str:
    """A script's path relative to the top script's folder, as a called script is found: the
    same whatever the working directory and however the top script was named."""
    base = os.path.dirname(os.path.abspath(top.path))
    try:
        return Path(os.path.relpath(os.path.abspath(path), base)).as_posix()
    except ValueError:  # another drive (Windows)
        return path


def _digest(line: str) -> str:
    return hashlib.sha256(line.encode("utf-8")).hexdigest()[:16]


def position_lines(
    script: Script, path: TimelinePath, enter: Callable[[Script, int], None] | None = None
) -> list[tuple[Script, int]]:
    """(script, line) of the saved position in every script the path passes through: the
    line of the step the walk is at in that script (a ``@call``'s, or the block's).
    ``enter(script, level)`` is called as the walk enters each script, before walking it."""
    out: list[tuple[Script, int]] = []
    steps: tuple[Step, ...] = script.timeline
    if enter is not None:
        enter(script, 0)
    try:
        for frame in path:
            step = steps[frame.step]
            if isinstance(step, TBlock):
                if frame.reaction < 0:
                    return [*out, (script, step.line)]
                steps = step.reactions[frame.reaction].body
            elif isinstance(step, TRepeat):
                steps = step.body
            elif isinstance(step, TIf):
                steps = step.then if frame.detail == 0 else step.orelse
            elif isinstance(step, TCall):
                out.append((script, step.line))
                script, steps = step.script, step.script.timeline
                if enter is not None:
                    enter(script, len(out))
            else:
                break
    except IndexError:
        pass
    raise StateFileError("the saved position is no longer a block of the script")


def fingerprint(script: Script, path: TimelinePath) -> list[dict[str, Any]]:
    """The digests of every line before the saved position, per script file."""
    prints = []
    for owner, line in position_lines(script, path):
        lines = Path(owner.path).read_text(encoding="utf-8").split("\n")
        digests = [_digest(text) for text in lines[: line - 1]]
        prints.append({"file": _key(script, owner.path), "line": line, "digests": digests})
    return prints


def save(
    target: Path,
    script: Script,
    path: TimelinePath,
    blocks: int,
    loop: TickLoop[Any],
    robot: MujocoRobot,
    ctx: Context,
    settings: RunSettings,
) -> None:
    """Write the state of a run about to start its ``blocks + 1``-th block, at ``path``."""
    m, d = robot.model, robot.data
    physics = np.empty(mujoco.mj_stateSize(m, PHYSICS))
    mujoco.mj_getState(m, d, physics, PHYSICS)
    state = {
        "format": FORMAT,
        "version": VERSION,
        "script": Path(script.path).name,
        "block": blocks + 1,
        "path": [list(f) for f in path],
        "fingerprint": fingerprint(script, path),
        "settings": {
            "tick": settings.tick,
            "seed": settings.seed,
            "perturb_mm": settings.perturb_mm,
            "disturb": [d.text for d in settings.disturb],
        },
        "clock": {"periods": loop.periods, "clock": loop.clock, "tick": loop.tick},
        "latest": [[_key(script, s), e, o.value] for (s, e), o in loop.latest.items()],
        "counts": dict(loop.counts),
        "contacts": ctx.point_sets,
        "stops": {str(f): [_point(c.tactile), _point(c.link)] for f, c in ctx.stops.items()},
        "results": ctx.results,
        **_beliefs(ctx),
        "robot": {
            "steps": robot.steps,
            "arm_target": _array(robot.arm_target),
            "hand_target": _array(robot.hand_target),
            "limp": [bool(x) for x in robot.limp],
            "saturated_since": _array(robot.safety.saturated_since),
            "saturation_logged": [bool(x) for x in robot.safety.saturation_logged],
        },
        "physics": {"spec": int(PHYSICS), "size": int(physics.size), "state": _array(physics)},
        "derived": {name: _array(getattr(d, name).ravel()) for name in DERIVED},
    }
    try:
        target.write_text(json.dumps(state, default=float) + "\n", encoding="utf-8")
    except OSError as e:
        raise DialError(f"cannot write the state file '{target}': {e.strerror or e}") from None


@dataclass(frozen=True)
class StateFile:
    """A state file as read: call :meth:`resume` on the script to go on with it."""

    source: Path
    data: dict[str, Any]
    settings: RunSettings

    def check(self, script: Script) -> Resume:
        """The runner's resume point, if ``script`` is the saved one with every line before
        the saved position unchanged; else a :class:`StateFileError` naming the first
        changed line as FILE:LINE:COL."""
        try:
            return self._check(script)
        except (KeyError, TypeError, ValueError) as e:  # fields of the wrong shape
            raise StateFileError(f"state file '{self.source}' is corrupt ({e})") from None

    def _check(self, script: Script) -> Resume:
        d = self.data
        name = Path(script.path).name
        if d["script"] != name:
            raise StateFileError(
                f"state file '{self.source}' was saved from script '{d['script']}', not '{name}'"
            )
        path = tuple(Frame(*f) for f in d["path"])
        prints = d["fingerprint"]

        def enter(owner: Script, level: int) -> None:  # lines before the position: unchanged?
            if level < len(prints):  # the file the script calls now, wherever it is run from
                self._unchanged(Path(owner.path), prints[level])

        where = position_lines(script, path, enter)
        if [line for _, line in where] != [p["line"] for p in prints]:
            owner, line = where[-1]
            raise StateFileError(f"{owner.path}:{line}:1: the saved block is no longer here")
        clock = d["clock"]
        # Outcomes by script as the runner keys them: this run's path of each script (a file
        # saved before paths were relative to the top script's folder holds them as run).
        paths = {_key(script, s.path): s.path for s in scripts_of(script)}
        paths.update({s.path: s.path for s in scripts_of(script)})
        latest = {(paths.get(s, s), e): Outcome(o) for s, e, o in d["latest"]}
        return Resume(
            path,
            d["block"] - 1,
            clock["periods"],
            clock["clock"],
            clock["tick"],
            latest,
            d["counts"],
        )

    @staticmethod
    def _unchanged(file: Path, saved: dict[str, Any]) -> None:
        try:
            lines = file.read_text(encoding="utf-8").split("\n")
        except (OSError, UnicodeDecodeError) as e:
            raise StateFileError(f"cannot read '{file}' to check it: {e}") from None
        for k, digest in enumerate(saved["digests"], start=1):
            if k > len(lines) or _digest(lines[k - 1]) != digest:
                raise StateFileError(
                    f"{file}:{k}:1: this line changed since the state was saved; only lines "
                    f"from the saved position (line {saved['line']}) on may change"
                )

    def restore(self, robot: MujocoRobot, ctx: Context) -> None:
        """Put the saved physics, driver and recorded sets back (on the same scene)."""
        try:
            self._restore(robot, ctx)
        except (KeyError, TypeError, ValueError) as e:  # base64, sizes, missing fields
            raise StateFileError(f"state file '{self.source}' is corrupt ({e})") from None

    def _restore(self, robot: MujocoRobot, ctx: Context) -> None:
        d = self.data
        m = robot.model
        physics = d["physics"]
        if physics["spec"] != int(PHYSICS) or physics["size"] != mujoco.mj_stateSize(m, PHYSICS):
            raise StateFileError(
                f"state file '{self.source}' does not fit this scene's model (state size)"
            )
        state = _floats(physics["state"], physics["size"], "the physics state")
        mujoco.mj_setState(m, robot.data, state, PHYSICS)
        mujoco.mj_forward(m, robot.data)
        for name in DERIVED:
            target = getattr(robot.data, name)
            target.flat[:] = _floats(d["derived"][name], target.size, name)
        r = d["robot"]
        robot.steps = int(r["steps"])
        robot.arm_target = _floats(r["arm_target"], robot.arm_target.size, "arm_target")
        robot.hand_target = _floats(r["hand_target"], 16, "hand_target")
        robot.set_limp(slice(None), _flags(r["limp"], robot.limp.size, "limp"))
        drives = robot.safety.saturated_since.size
        robot.safety.restore(
            _floats(r["saturated_since"], drives, "saturated_since"),
            _flags(r["saturation_logged"], drives, "saturation_logged"),
        )
        robot.disturbances.resume_at(robot.steps)
        ctx.point_sets.update(d["contacts"])
        for f, (tactile, link) in d.get("stops", {}).items():
            ctx.stops[int(f)] = Touch(_stop_point(tactile), _stop_point(link))
        ctx.results.update(d["results"])
        _restore_beliefs(d, ctx)


def _beliefs(ctx: Context) -> dict[str, Any]:
    """The world model's part of a state file: believed poses and sizes, what is held."""
    held = {
        body: {
            "fingers": list(h.fingers),
            "relative": [_array(h.relative[0]), _array(h.relative[1])],
            "grasped": [_array(h.grasped[0]), _array(h.grasped[1])],
            "on": h.on,
        }
        for body, h in ctx.world_model.held.items()
    }
    return {
        "believed": {body: _array(pos) for body, (pos, _) in ctx.believed.items()},
        "believed_rot": {body: _array(rot) for body, (_, rot) in ctx.believed.items()},
        "sizes": {body: _array(size) for body, size in ctx.world_model.sizes.items()},
        "learned": ctx.world_model.changed,
        "held": held,
    }


def _restore_beliefs(d: dict[str, Any], ctx: Context) -> None:
    """The world model as the run left it: believed poses and sizes, what the hand holds."""
    rots = d.get("believed_rot", {})
    for body, pos in d.get("believed", {}).items():
        if body in ctx.believed:
            rot = ctx.believed[body][1]
            if body in rots:
                rot = _floats(rots[body], 9, f"believed {body}").reshape(3, 3)
            ctx.believed[body] = (_floats(pos, 3, f"believed {body}"), rot)
    model = ctx.world_model
    model.changed = bool(d.get("learned", False))
    for body, size in d.get("sizes", {}).items():
        model.sizes[body] = _floats(size, 3, f"size of {body}")
    for body, held in d.get("held", {}).items():
        relative, grasped = (
            (_floats(p, 3, body), _floats(r, 9, body).reshape(3, 3)) for p, r in (
                held["relative"], held["grasped"]
            )
        )  # fmt: skip
        fingers = tuple(int(f) for f in held["fingers"])
        model.held[body] = Held(fingers, relative, grasped, str(held.get("on", "")))


def load(source: Path) -> StateFile:
    """Read a state file; a one-line :class:`StateFileError` if it is not one dial can use."""
    try:
        data = json.loads(source.read_text(encoding="utf-8"))
    except OSError as e:
        raise StateFileError(f"cannot read state file '{source}': {e.strerror or e}") from None
    except (UnicodeDecodeError, json.JSONDecodeError):
        raise StateFileError(f"state file '{source}' is corrupt or truncated (not JSON)") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise StateFileError(f"'{source}' is not a dial state file")
    if data.get("version") != VERSION:
        raise StateFileError(
            f"state file '{source}' has format version {data.get('version')!r}; this dial "
            f"reads version {VERSION}: save it again with this dial"
        )
    try:
        s = data["settings"]
        disturb = tuple(parse_disturbance(str(text)) for text in s["disturb"])
        settings = RunSettings(float(s["tick"]), int(s["seed"]), float(s["perturb_mm"]), disturb)
        for key in (
            "script",
            "block",
            "path",
            "fingerprint",
            "clock",
            "latest",
            "counts",
            "contacts",
            "results",
            "robot",
            "physics",
            "derived",
        ):
            data[key]
        for frame in data["path"]:
            Frame(*map(int, frame))
        if type(data["block"]) is not int or data["block"] < 1:
            raise ValueError(f"block {data['block']!r}")
    except (KeyError, TypeError, ValueError) as e:
        raise StateFileError(f"state file '{source}' is corrupt or truncated ({e})") from None
    return StateFile(source, data, settings)
