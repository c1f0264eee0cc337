"""The preview's walk of a timeline: blocks tick by tick; branches, reactions, loops, calls.

A block is walked as the runner walks it (tick by tick, runs started in line order, each
fixed-length run stepped every control period on its progress in tick time), with the
set-points going straight to the pose: the arm and the fingers are where they are
commanded. The pose is checked whenever it has moved a little (see :data:`ARM_STEP`), and
at every period while a watched span is watched. Indeterminate runs are previewed at their
start, at once (:mod:`dial.preview.motions`). Both branches of an ``@if`` are previewed from
the same pose, and the walk goes on from the branch the previewed outcomes choose; every
``@on`` reaction is previewed from where its block ends (or where its monitor fired, from
which the walk then goes on); a loop's body once; a call's timeline in place.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

from dial.backend.driver import CONTROL_PERIOD
from dial.errors import DialError
from dial.parser.ast import Condition
from dial.parser.script import Run, Script, Step, TBlock, TCall, TIf, TOn, TRepeat, Watch
from dial.preview.motions import sensed
from dial.preview.moves import AtOnce, Making, P, Sensed, Stepped
from dial.preview.places import Place, Places
from dial.preview.report import Counts, Problems
from dial.preview.scene import Hit, Scene, State, finger_group
from dial.robot.protocol import Course
from dial.robot.snapshot import FloatArray, Snapshot
from dial.scheduler.primitive import Now, Outcome, Primitive, progress_after
from dial.scheduler.types import RunInfo

ARM_STEP = np.radians(0.25)  # rad of any arm joint between two checks of a moving pose
HAND_STEP = np.radians(1.0)  # rad of any hand joint
Latest = dict[tuple[str, str], Outcome]


@dataclass
class Active:
    """A fixed-length run being stepped: where it is written, and its progress;
    ``finished``: the problems with where it got; ``label``: what it does at a progress."""

    place: Place
    run: Run
    prim: Primitive[Snapshot]
    effectors: frozenset[str]
    span: int  # its executing ticks, in control periods
    start_clock: int
    finished: Callable[[], list[str]]
    label: Callable[[float], str]
    progress: float = 0.0


class Starting(NamedTuple):
    """The run being started: where it is written, and its place in the timeline."""

    place: Place
    info: RunInfo


@dataclass(frozen=True)
class Bookmark:
    """Where a walk is: the scene, the latest outcomes, the contacts going on and whose."""

    state: State
    latest: Latest
    ongoing: dict[tuple[str, str, str], tuple[Place, str]]


@dataclass(frozen=True)
class Panel:
    """A block's end, for the storyboard."""

    label: str  # the path through the timeline that led here
    place: str  # FILE:LINE of the block
    events: tuple[str, ...]
    qpos: FloatArray
    trace: FloatArray  # (N, 3) tool positions through the block
    problems: int
    note: str


class Walk:
    """Walks a script's timeline over a :class:`Scene`; collects problems and panels."""

    def __init__(self, scene: Scene, periods_per_tick: int, traces: bool = True) -> None:
        """``traces``: keep the tool's path through each block (only a storyboard draws it)."""
        self.scene, self.n, self.traces = scene, periods_per_tick, traces
        self.problems = Problems()
        self.counts = Counts()
        self.panels: list[Panel] = []
        self.latest: Latest = {}
        self.active: list[Active] = []
        self.owner: dict[str, Place] = {}  # effector -> the run that commanded it last
        self.current: Place | None = None  # a run previewed at once
        self.why = ""  # on a path the preview does not take: why
        self.clock = 0
        self.block_place = Place("", 0, 0, "")
        self.trace: list[FloatArray] = []
        self.ongoing: dict[tuple[str, str, str], tuple[Place, str]] = {}
        self.seen = (scene.robot.arm_target.copy(), scene.robot.hand_target.copy())
        self.places = Places()  # statement places, the world files read once per preview
        self.starting: Starting | None = None  # the run a move is starting

    # -- the timeline ------------------------------------------------------------------------------
    def steps(self, script: Script, steps: tuple[Step, ...], label: str) -> None:
        for step in steps:
            if isinstance(step, TBlock):
                self.block(script, step, label)
            elif isinstance(step, TRepeat):
                self.counts.loops += 1
                cond = f" {step.condition}" if step.condition is not None else ""
                tag = f"@repeat {step.kind if step.kind != 'count' else step.count}{cond}"
                self.steps(script, step.body, f"{label}{tag} (once) / ")
            elif isinstance(step, TIf):
                self.branch(script, step, label)
            elif isinstance(step, TCall):
                self.steps(step.script, step.script.timeline, f"{label}@call {step.target} / ")
            else:  # @resume, @retry, @abort: the reaction ends here
                return

    def branch(self, script: Script, step: TIf, label: str) -> None:
        """Both branches from the same pose; go on from the one the outcomes choose."""
        self.counts.branches += 1
        value = self.test(script, step.condition)
        where = f"the @if {step.condition} of {Path(script.path).name}:{step.line}"
        start = self.save()
        untaken = " (not taken)"
        with self.aside("" if value else f"{where} is previewed false"):
            tag = f"@if {step.condition}{'' if value else untaken}"
            self.steps(script, step.then, f"{label}{tag} / ")
        then = self.save()
        self.restore(start)
        with self.aside(f"{where} is previewed true" if value else ""):
            tag = f"@else ({step.condition}){untaken if value else ''}"
            self.steps(script, step.orelse, f"{label}{tag} / ")
        if value:
            self.restore(then)

    @contextmanager
    def aside(self, why: str) -> Iterator[None]:
        """Walk a path the preview does not take (``why`` says so): its problems are notes."""
        before = self.why
        self.why = before or why
        try:
            yield
        finally:
            self.why = before

    def test(self, script: Script, cond: Condition) -> bool:
        if cond.event in script.condition_only:  # a sensing event: sensed now
            outcome = script.events[cond.event].args.preview().begin(self)
            if outcome is not None:
                self.latest[(script.path, cond.event)] = outcome
        return (self.latest.get((script.path, cond.event)) is Outcome.DONE) != cond.negated

    def save(self) -> Bookmark:
        return Bookmark(self.scene.save(), dict(self.latest), dict(self.ongoing))

    def restore(self, saved: Bookmark) -> None:
        self.scene.restore(saved.state)
        self.latest, self.ongoing = dict(saved.latest), dict(saved.ongoing)
        self.seen = (self.scene.robot.arm_target.copy(), self.scene.robot.hand_target.copy())

    # -- a block -----------------------------------------------------------------------------------
    def block(self, script: Script, block: TBlock, label: str) -> None:
        self.counts.blocks += 1
        self.block_place = Place(script.path, block.line, 1, "(block)")
        before = len(self.problems)
        self.trace = [self.scene.tool()[0]]
        starts: dict[int, list[Run]] = defaultdict(list)
        for run in block.runs:
            starts[run.start].append(run)
        watching: list[Watch] = []
        fired: TOn | None = None
        for k in range(1, block.length + 1):
            watching += [w for w in block.watches if w.start == k]
            for run in starts[k]:
                self.start(script, run)
            fired = self.periods(script, block, k, watching)
            if fired is not None:
                break
            self.finish(script, k)
            watching = [w for w in watching if w.end != k]
        for a in self.active:
            if fired is not None:
                self.latest[(a.place.path, a.run.event)] = Outcome.PREEMPTED
            a.prim.stop()
        self.active = []
        self.look()
        note = f"preempted: @on {fired.condition} fired" if fired is not None else ""
        events = tuple(dict.fromkeys(r.event for r in block.runs))
        place = f"{script.path}:{block.line}"
        problems = len(self.problems) - before
        qpos = self.scene.data.qpos.copy()
        self.panels.append(Panel(label, place, events, qpos, np.array(self.trace), problems, note))
        self.reactions(script, block, label, fired)

    def periods(self, script: Script, block: TBlock, k: int, watching: list[Watch]) -> TOn | None:
        """Step the runs executing in tick ``k``, period by period; a monitor that fires."""
        moving = [a for a in self.active if a.run.start <= k <= a.run.exec_end]
        if not moving and not watching:
            self.clock += self.n
            return None
        snapshot = self.scene.robot.snapshot()
        writes = [self.course(a, k, snapshot) for a in moving]
        for i in range(self.n):
            self.clock += 1
            for a, write in zip(moving, writes, strict=True):
                a.progress = self.progress(a, self.clock)
                write(i)
            if watching:
                self.look()
                fired = self.fires(script, block, watching)
                if fired is not None:
                    return fired
            else:
                self.glance()
        return None

    def progress(self, a: Active, clock: int) -> float:
        """A run's progress in tick time at the end of period ``clock``, as the runner has it."""
        return progress_after(clock - a.start_clock, a.span, self.n)

    def course(self, a: Active, k: int, snapshot: Snapshot) -> Course:
        """A writer of the run's set-points in the ``i``-th period of tick ``k``: an open-loop
        run's course (what its step would write, bit for bit, worked out for the whole tick
        at once), else its step."""
        if a.prim.open_loop:
            return a.prim.course(self.clock - a.start_clock + 1, self.n)

        def step(i: int) -> None:
            a.prim.step(snapshot, Now(0.0, k, a.progress, 0.0, False))

        return step

    def fires(self, script: Script, block: TBlock, watching: list[Watch]) -> TOn | None:
        """The first ``@on`` (in file order) whose watched contact condition holds now."""
        for on in block.reactions:
            for watch in watching:
                if watch.event != on.condition.event:
                    continue
                touching = self.scene.touching({finger_group(watch.contact.finger)})
                if touching != on.condition.negated:
                    outcome = Outcome.MISSED if on.condition.negated else Outcome.DONE
                    self.latest[(script.path, on.condition.event)] = outcome
                    return on
        return None

    def reactions(self, script: Script, block: TBlock, label: str, fired: TOn | None) -> None:
        """Every reaction from the block's end; the walk goes on from the one that fired."""
        if not block.reactions:
            return
        end = self.save()
        keep = end
        for on in block.reactions:
            self.restore(end)
            self.counts.reactions += 1
            how = "" if on is fired else ", not fired in the preview"
            where = f"the monitor @on {on.condition} of {Path(script.path).name}:{on.line}"
            with self.aside("" if on is fired else f"{where} does not fire in the preview"):
                self.steps(script, on.body, f"{label}@on {on.condition} (line {on.line}{how}) / ")
            if on is fired:
                keep = self.save()
        self.restore(keep)

    # -- runs: each instruction's record says how it moves (dial.preview.moves) -------------
    def start(self, script: Script, run: Run) -> None:
        event = script.events[run.event]
        place = Place(script.path, run.line, run.span.col or 1, run.event)
        for effector in event.effectors:
            self.owner[effector] = place
        self.scene.pose()
        self.starting = Starting(place, RunInfo(event, run, script.path, self.n, CONTROL_PERIOD))
        outcome = event.args.preview().begin(self)
        if outcome is not None:
            self.latest[(script.path, run.event)] = outcome

    def stepped(self, move: Stepped[P]) -> Outcome | None:
        """Start a fixed-length run's primitive; :meth:`periods` steps it from now on."""
        assert self.starting is not None, "a move begins in Walk.start"
        place, info = self.starting
        written = " ".join(w.text for p in info.event.definition.params for w in p.words)
        scene = self.scene
        prim = move.make(Making(scene.ctx, info.allotment, self.places, written))
        try:
            prim.start(scene.robot.snapshot())
        except DialError as e:
            self.problems.add(place, str(e), self.why)
            return Outcome.ERROR
        for message in move.started(scene, prim):
            self.problems.add(place, message, self.why)
        arm, hand = move.counts(prim)
        self.counts.arm += arm
        self.counts.hand += hand

        def finished() -> list[str]:
            return move.finished(scene, prim)

        def label(progress: float) -> str:
            return move.label(prim, progress)

        effectors, span = info.event.effectors, info.span
        self.active.append(
            Active(place, info.run, prim, effectors, span, self.clock, finished, label)
        )
        return None

    def at_once(self, move: AtOnce) -> Outcome:
        """A guarded move or a grasp, previewed whole now."""
        assert self.starting is not None, "a move begins in Walk.start"
        place = self.current = self.starting.place
        self.counts.arm += move.arm
        self.counts.hand += not move.arm
        try:
            found = move.motion(self.scene, self.record)
        finally:
            self.current = None
        for message in found.problems:
            self.problems.add(place, message, self.why)
        self.look()
        return found.outcome

    def sensed(self, move: Sensed) -> Outcome:
        return sensed(self.scene, move.finger)

    def finish(self, script: Script, k: int) -> None:
        """End the runs whose last executing tick ``k`` was."""
        for a in [a for a in self.active if a.run.exec_end == k]:
            self.scene.pose()
            ended = a.prim.finish(self.scene.robot.snapshot())
            for message in (*ended.warnings, *a.finished()):
                self.problems.add(a.place, message, self.why)
            self.latest[(script.path, a.run.event)] = ended.outcome
            a.prim.stop()
            self.active.remove(a)
        self.glance()

    # -- looking at the pose -----------------------------------------------------------------------
    def glance(self) -> None:
        """Look at the pose if it moved enough since it was last looked at."""
        arm, hand = self.scene.robot.arm_target, self.scene.robot.hand_target
        seen_arm, seen_hand = self.seen
        if max(map(abs, (arm - seen_arm).tolist())) > ARM_STEP or (
            hand.tobytes() != seen_hand.tobytes()  # the hand seldom moves: compare it fast
            and np.abs(hand - seen_hand).max() > HAND_STEP
        ):
            self.look()

    def look(self) -> None:
        self.scene.pose()
        self.record()

    def record(self) -> None:
        """Record the posed scene's problems, each on the run that caused it."""
        robot = self.scene.robot
        self.seen = (robot.arm_target.copy(), robot.hand_target.copy())
        if self.traces:
            self.trace.append(self.scene.tool_position())
        ongoing: dict[tuple[str, str, str], tuple[Place, str]] = {}
        for hit in self.scene.hits():
            # A contact that goes on from the last look stays with the run that made it.
            place, context = self.ongoing.get(hit.key) or self.blame(hit)
            self.problems.hit(place, hit, context, self.why)
            ongoing[hit.key] = place, context
        self.ongoing = ongoing

    def blame(self, hit: Hit) -> tuple[Place, str]:
        """The run that moves a part of the contact (else the arm, which moves the hand into
        the world), and what it is doing; else the run that moved one last."""
        if self.current is not None:
            return self.current, ""
        effectors = hit.effectors
        movers = effectors if hit.key[0] == "self" else (*effectors, "arm")
        for who in movers:
            moving = [a for a in self.active if who in a.effectors]
            if moving:
                a = moving[-1]
                return a.place, a.label(a.progress)
        for who in movers:
            if who in self.owner:
                return self.owner[who], ""
        return self.block_place, ""
