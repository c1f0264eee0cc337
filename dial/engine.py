"""Run a checked script in its scene: world model, physics, primitives, criteria.

This is the one place that joins the layers: the parser's script, the
scheduler's runner, the primitives, and the MuJoCo backend.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, TextIO

import mujoco
import numpy as np
import trio

from dial.backend.driver import MujocoRobot
from dial.backend.ik import ArmIK
from dial.backend.model import ARM_HOME, RobotIndex, hand_ctrl, load_model
from dial.errors import DialError
from dial.parser.script import Script
from dial.primitives import Context, make_factory
from dial.primitives.context import location_pose, rpy_matrix
from dial.scene.evaluate import measure
from dial.scene.resolve import resolve_scene, worlds_dir
from dial.scene.world import World, load_world
from dial.scheduler.log import EventLog
from dial.scheduler.runner import Runner, RunSummary

DEFAULT_TICK = 0.25  # s, when neither the script (@tick) nor the command line sets one
SETTLE_S = 0.5  # objects settle on the table before the script starts
# Where the tool starts when the world file has no "home" location: high above the tables,
# pointing down (world m; rpy as in world files).
START = ((0.40, 0.0, 0.80), (np.pi, 0.0, 0.0))


@dataclass(frozen=True)
class Watched:
    """What an observer may read, and never write: the robot, the scene's world, the log."""

    robot: MujocoRobot
    world: World
    log: EventLog


class Observer(Protocol):
    """Watches a run without changing it: recording, video, viewers (dial.recording).

    ``begin`` is called after the scene has settled, ``period`` after every control period with
    the periods simulated so far and the current tick: an observer samples on those integers
    (simulated time), never on wall time.
    """

    def begin(self, run: Watched) -> None: ...

    def period(self, periods: int, tick: int) -> None: ...

    def end(self, result: RunResult | None) -> None:
        """After the criteria are measured; ``result`` is None after an interrupt or error."""
        ...


@dataclass
class RunOptions:
    tick: float | None = None
    speed: float = 1.0
    seed: int = 0
    perturb_mm: float = 0.0
    realtime: bool = False
    log: TextIO | None = None
    on_tick: Callable[[int, float, list[str]], None] | None = None
    observers: list[Observer] = field(default_factory=list)


@dataclass
class RunResult:
    summary: RunSummary
    world: World
    success: dict[str, bool]
    details: dict[str, str]
    results: dict[str, Any]
    wall_time: float
    physics_steps: int
    log: EventLog
    final_qpos: list[float] = field(default_factory=list)
    cpu_time: float = 0.0  # s of this process's CPU over the same span as wall_time

    @property
    def ok(self) -> bool:
        return self.summary.ok and all(self.success.values())


def tick_length(script: Script, options: RunOptions) -> float:
    tick = options.tick if options.tick is not None else (script.tick or DEFAULT_TICK)
    if not (math.isfinite(options.speed) and options.speed > 0):
        raise DialError(f"--speed must be a positive number, got {options.speed:g}")
    return tick / options.speed


def _world(script: Script) -> World:
    scene = script.program.scene
    text = script.scene_override or (scene.text if scene is not None else None)
    if text is None:
        raise DialError(
            f"{script.path}: the script names no scene; add '@scene NAME' or run it with --scene"
        )
    return load_world(resolve_scene(text, Path(script.path).resolve().parent))


def _scene_bodies(model: mujoco.MjModel, world: World) -> list[int]:
    """Bodies a perturbation moves: every free body, and the world file's fixed objects."""
    named = {
        int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b)) for b in world.objects.values()
    }
    free = {
        int(model.jnt_bodyid[j])
        for j in range(model.njnt)
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE
    }
    return sorted(named | free)


def _perturb(
    model: mujoco.MjModel, data: mujoco.MjData, world: World, mm: float, seed: int
) -> list[float]:
    """Shift the scene's objects by ``mm`` in a seeded horizontal direction."""
    if mm <= 0:
        return [0.0, 0.0, 0.0]
    angle = np.random.default_rng(seed).uniform(0.0, 2.0 * np.pi)
    shift = np.array([np.cos(angle), np.sin(angle), 0.0]) * mm / 1000.0
    for body in _scene_bodies(model, world):
        joint = int(model.body_jntadr[body])
        if joint >= 0 and model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_FREE:
            adr = int(model.jnt_qposadr[joint])
            data.qpos[adr : adr + 3] += shift
        elif model.body_parentid[body] == 0 and model.body_jntnum[body] == 0:
            model.body_pos[body] += shift
    return [float(x) for x in shift]


def prepare(script: Script, options: RunOptions, log: EventLog) -> tuple[MujocoRobot, Context]:
    """Load the scene, place the robot at home, settle, perturb; build the primitives' context."""
    world = _world(script)
    model = load_model(world.model_path)
    data = mujoco.MjData(model)
    index = RobotIndex.from_model(model)
    mujoco.mj_forward(model, data)
    believed = {
        model.body(b).name: (data.xpos[b].copy(), data.xmat[b].reshape(3, 3).copy())
        for b in _scene_bodies(model, world)
    }
    ik = ArmIK()
    if "home" in world.locations:
        pos, rot = location_pose(world, believed, "home")
    else:
        pos, rot = np.array(START[0]), rpy_matrix(START[1])
    home = ik.solve(pos, rot, np.array(ARM_HOME), "the start pose (location 'home')")
    data.qpos[index.arm_qpos] = home
    data.ctrl[index.arm_actuators] = home
    data.ctrl[index.tendon_actuators] = hand_ctrl(data.qpos[index.hand_qpos])
    shift = _perturb(model, data, world, options.perturb_mm, options.seed)
    mujoco.mj_forward(model, data)
    for _ in range(round(SETTLE_S / model.opt.timestep)):
        mujoco.mj_step(model, data)
    # A bundled world by its file name; another by its absolute path, so that dial replay
    # finds it from anywhere.
    bundled = world.path.parent == worlds_dir().resolve()
    where = world.path.name if bundled else str(world.path)
    log.write("scene", scene=world.name, world=where, perturb=shift, seed=options.seed)
    robot = MujocoRobot(model, data, log)
    return robot, Context(robot, world, believed, ik)


def _fan_out(observers: list[Observer]) -> Callable[[int, int], None] | None:
    """One callback for the runner; None (no per-period cost) without observers."""
    if len(observers) <= 1:
        return observers[0].period if observers else None

    def period(periods: int, tick: int) -> None:
        for observer in observers:
            observer.period(periods, tick)

    return period


def run(script: Script, options: RunOptions) -> RunResult:
    """Run ``script`` to the end (or its abort) and evaluate the scene's criteria."""
    log = EventLog(options.log)
    tick = tick_length(script, options)
    robot, ctx = prepare(script, options, log)
    if options.realtime:
        robot.pace = 1.0
    begun: list[Observer] = []
    result: RunResult | None = None
    try:  # observers end also on an interrupt or an error: a recording keeps what was seen
        for observer in options.observers:
            observer.begin(Watched(robot, ctx.world, log))
            begun.append(observer)
        factory = make_factory(ctx)
        runner = Runner(robot, factory, tick, log, on_tick=options.on_tick, observe=_fan_out(begun))
        result = _run(script, runner, robot, ctx)
        return result
    finally:
        for observer in begun:
            observer.end(result)


def _run(script: Script, runner: Runner, robot: MujocoRobot, ctx: Context) -> RunResult:
    start, cpu = time.perf_counter(), time.process_time()
    summary = trio.run(runner.run, script)
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    success: dict[str, bool] = {}
    details: dict[str, str] = {}
    for criterion in ctx.world.criteria:
        ok, detail = measure(criterion, robot.model, robot.data, ctx.results)
        success[criterion.name] = bool(ok)
        details[criterion.name] = detail
    return RunResult(
        summary,
        ctx.world,
        success,
        details,
        dict(ctx.results),
        wall,
        robot.steps,
        runner.log,
        [float(x) for x in robot.data.qpos],
        cpu,
    )
