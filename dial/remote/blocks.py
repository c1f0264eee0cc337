"""``--split block`` at the robot: run the blocks the operator sends, at their ticks.

The operator walks the timeline (NASREM level 4) and sends each block tagged with the
tick it must start at; a condition it needs is tested here, at its tick, and reported.
The robot runs a block (levels 3 and below: guards, grasps, contact waits, watched spans
and their reactions) with the runner's own tick loop. A block is described on the wire by
:func:`describe` (its runs with their instructions and parameters, its watched spans and
its reactions); the robot finds the block at that line of the script it checked against
its own world and runs it only if the description matches its own.

Between blocks the robot holds every effector and lets ticks pass (an ``idle`` record
starts each such span). A command whose tick has passed is refused ``late`` and the robot
holds; a command chained ``after`` one it did not run is refused ``dropped``.
"""

from __future__ import annotations

import dataclasses
import queue
import time

import trio

from dial.engine.observe import Watched, fan_out
from dial.engine.result import RunResult, measure_criteria
from dial.engine.setup import Factory, prepare
from dial.parser.script import (
    Run,
    Script,
    Step,
    TAbort,
    TBlock,
    TCall,
    TIf,
    TRepeat,
    TResume,
    TRetry,
    Watch,
    iter_steps,
    scripts_of,
)
from dial.remote.protocol import Message
from dial.remote.session import Session
from dial.remote.telemetry import RobotConfig, Telemetry, disturbances
from dial.robot.snapshot import Snapshot
from dial.scheduler.log import EventLog, clean
from dial.scheduler.position import Frame, TimelinePath
from dial.scheduler.runner import Runner
from dial.scheduler.ticks import TickLoop
from dial.scheduler.types import Interrupted, RunAborted

IDLE = TBlock(0, 1, ())  # one tick with no run: every effector holds its last command


def describe(script: Script, step: Step) -> dict[str, object]:
    """A step as it travels: plain JSON, the same on both sides for the same step."""
    if isinstance(step, TBlock):
        return {
            "block": {
                "line": step.line,
                "length": step.length,
                "runs": [_run(script, r) for r in step.runs],
                "watches": [_watch(w) for w in step.watches],
                "reactions": [
                    {
                        "condition": str(on.condition),
                        "line": on.line,
                        "body": [describe(script, s) for s in on.body],
                    }
                    for on in step.reactions
                ],
            }
        }
    if isinstance(step, TRepeat):
        body = [describe(script, s) for s in step.body]
        condition = None if step.condition is None else str(step.condition)
        return {"repeat": {"kind": step.kind, "count": step.count, "if": condition, "body": body}}
    if isinstance(step, TIf):
        then = [describe(script, s) for s in step.then]
        orelse = [describe(script, s) for s in step.orelse]
        return {"if": {"condition": str(step.condition), "then": then, "else": orelse}}
    if isinstance(step, TCall):
        return {"call": {"target": step.target, "line": step.line}}
    if isinstance(step, TResume):
        return {"resume": {"line": step.line}}
    if isinstance(step, TRetry):
        return {"retry": {"max": step.max, "line": step.line}}
    assert isinstance(step, TAbort)
    return {"abort": {"message": step.message, "line": step.line}}


def _run(script: Script, run: Run) -> dict[str, object]:
    event = script.events[run.event]
    args: object = event.args
    if dataclasses.is_dataclass(args) and not isinstance(args, type):
        args = dataclasses.asdict(args)
    return {
        "event": run.event,
        "line": run.line,
        "start": run.start,
        "exec_end": run.exec_end,
        "hold_end": run.hold_end,
        "effectors": sorted(run.effectors),
        "instruction": event.instruction.name,
        "params": clean(args),
    }


def _watch(watch: Watch) -> dict[str, object]:
    return {"event": watch.event, "line": watch.line, "start": watch.start, "end": watch.end}


class BlockRunner(Runner[Snapshot]):
    """The runner, taking its blocks and tests from the operator's commands."""

    session: Session
    last = 0  # the seq of the last command run (a chained command must follow it)
    _head: Message | None = None
    _idle = False

    async def _main(self, loop: TickLoop[Snapshot], script: Script, path: TimelinePath) -> None:
        steps = {
            (s.path, step.line): (s, step)
            for s in scripts_of(script)
            for step in iter_steps(s.timeline)
            if isinstance(step, TBlock | TIf | TRepeat)
        }
        self._path.append(Frame(0))
        await self._first(loop)
        while True:
            command = self._next()
            if command is not None and command.integer("after") != self.last:
                self._head = None
                why = f"it follows command {command.integer('after')}, which did not run"
                self._refuse(command, "dropped", why, loop.tick)
                continue
            if command is None or command.integer("tick") > loop.tick + 1:
                await self._idle_tick(loop, script)
                continue
            self._head, self._idle = None, False
            seq, ident = command.integer("seq"), command.text("id")
            if command.integer("tick") <= loop.tick:
                why = (
                    f"tick {command.integer('tick')} had passed (the robot is at tick {loop.tick})"
                )
                self._refuse(command, "late", why + "; the robot holds", loop.tick)
                continue
            if command.type == "end":
                self.last = seq
                if "error" in command.fields:
                    raise RunAborted(command.text("error"), None, loop.tick)
                return
            found = steps.get((command.text("script"), _line(command)))
            problem = self._mismatch(command, found)
            if problem is not None:
                self._refuse(command, "mismatch", problem, loop.tick)
                continue
            assert found is not None
            owner, step = found
            fields: dict[str, object] = {}
            if isinstance(step, TBlock):
                await self._block(loop, owner, step, Frame(0), ())
            else:
                assert isinstance(step, TIf | TRepeat)
                fields["value"] = self._test(loop, owner, step.condition)
            self.last = seq
            self.session.report(
                "result", seq=seq, id=ident, tick=loop.tick, t=round(loop.sim_time, 6), **fields
            )

    async def _first(self, loop: TickLoop[Snapshot]) -> None:
        """Before the first command the robot's clock stands still (as a local run's before
        its first tick); then pacing counts from there."""
        while self._next() is None:
            if self.stop.signal is not None:
                raise Interrupted(self.stop.signal)
            await trio.sleep(0.002)
        if loop.pace is not None:
            loop.t0 = trio.current_time()

    def _next(self) -> Message | None:
        if self._head is None:
            try:
                self._head = self.session.commands.get_nowait()
            except queue.Empty:
                return None
        return self._head

    async def _idle_tick(self, loop: TickLoop[Snapshot], script: Script) -> None:
        if not self._idle:
            self._idle = True
            self.log.write("idle", tick=loop.tick + 1, t=loop.sim_time)
        await loop.block(script, IDLE)

    def _refuse(self, command: Message, code: str, message: str, tick: int) -> None:
        """Refuse a command: the robot's tick and the command it follows go with it."""
        seq, ident, after = command.integer("seq"), command.text("id"), command.integer("after")
        self.session.report(
            "refused", seq=seq, id=ident, code=code, message=message, tick=tick, after=after
        )

    @staticmethod
    def _mismatch(command: Message, found: tuple[Script, Step] | None) -> str | None:
        """Why the robot will not run this command's step (None: it matches the robot's)."""
        where = f"line {_line(command)} of {command.text('script')}"
        if command.type not in ("block", "test"):
            return f"a '{command.type}' command has no place in a block session"
        if found is None:
            return f"the robot's checked script has no block or condition at {where}"
        owner, step = found
        if command.type == "block":
            if not isinstance(step, TBlock) or describe(owner, step) != {
                "block": command.obj("block")
            }:
                return f"the block at {where} differs from the robot's (its world binds it so)"
        elif not isinstance(step, TIf | TRepeat) or str(step.condition) != command.text(
            "condition"
        ):
            return f"the condition at {where} differs from the robot's"
        return None


def _line(command: Message) -> int:
    if command.type == "block":
        line = command.obj("block").get("line")
        return line if isinstance(line, int) else -1
    return command.integer("line", -1)


def run_blocks(
    session: Session,
    config: RobotConfig,
    script: Script,
    first: Message,
    telemetry: Telemetry,
) -> RunResult:
    """A ``--split block`` session's run: set up as ``dial run`` does, then take commands."""
    from dial.remote.session import Tee

    log = EventLog(Tee(session))
    disturb = disturbances(config.disturb)
    robot, ctx = prepare(script, log, config.perturb, config.seed, disturb)
    telemetry.begin(Watched(robot, ctx.world, log))
    runner = BlockRunner(
        robot,
        Factory(ctx),
        first.number("tick_length"),
        log,
        observe=fan_out([telemetry]),
        pace=config.pace,
        stop=session.stop,
    )
    runner.session = session
    runner.last = first.integer("seq")  # 'open': the first block follows it
    start, cpu = time.perf_counter(), time.process_time()
    summary = trio.run(runner.run, script)
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    result = RunResult(
        summary,
        ctx.world,
        measure_criteria(ctx.world, robot.model, robot.data, ctx.results),
        dict(ctx.results),
        wall,
        cpu,
        robot.steps,
        log,
        [float(x) for x in robot.data.qpos],
        config.disturb,
    )
    log.write("summary", **result.as_record())
    return result
