"""What the preview does with each instruction whose end the run cannot know in advance.

Fixed-length instructions run through their own primitives (:mod:`dial.primitives`), the
set-points going straight to the pose. The others are previewed at their start, at once:

- ``guarded_move`` travels its line in small steps until the moving arm (the hand) or
  finger first touches the world or an object other than what the hand holds, then stops
  there (outcome ``done``), or travels its full ``max`` (``missed``). No ``press``.
- ``grasp_force`` closes its joints until each finger touches something or reaches its
  limit; the free bodies the fingers touch are held from then on (``done`` when every
  tendon-watched finger touched something).
- sensing and the contact waits are ``done`` when their finger touches the world or an
  object, else ``missed`` (``get_*`` and fits: ``done``).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from dial.backend.ik import IKError
from dial.preview.moves import Check, Found
from dial.preview.places import Places
from dial.preview.scene import HAND, Scene, State, finger_group
from dial.primitives.arm import Planner, PumaProgram, PumaStatement
from dial.primitives.context import Context
from dial.scene.valii import Statement
from dial.scheduler.primitive import Allotment, Outcome

STEP = 0.002  # m: the step of a guarded move's line
BISECT = 5  # halvings of the last step once a guarded move touches (to 0.06 mm)
LAG = 0.003  # m: a guarded move whose tool or fingertip lags its line more cannot follow it
CLOSE_STEP = np.radians(0.5)  # rad: a grasp's closing step


class PreviewProgram(PumaProgram):
    """``puma_command "ex PROG"`` planned statement by statement: an unreachable statement
    is reported (naming the program, its line and the world file's line) and skipped, so
    that the rest is still previewed; ``labels`` names the statement of each planned
    segment, ``targets`` counts the statements."""

    def __init__(self, ctx: Context, allotted: Allotment, program: str, places: Places) -> None:
        super().__init__(ctx, allotted, program)
        self.places = places  # where statements are written (the walk's)
        self.labels: list[str] = []
        self.problems: list[str] = []
        self.targets = 0

    def plan(self, planner: Planner) -> None:
        name, world = self.program, self.ctx.world
        self.labels, self.problems = [], []
        self.targets = len(world.programs[name].statements)
        for st in world.programs[name].statements:
            place = self.places.statement(world.path, name, st.line)
            where = f"program {name} line {st.line}" + (f", {place}" if place else "")
            before = len(planner.segments)
            try:
                planner.statement(st, where)
            except IKError as e:
                self.problems.append(str(e))
            self.labels += [where] * (len(planner.segments) - before)

    def label_at(self, progress: float) -> str:
        """The statement the arm follows at ``progress`` (as :meth:`step` picks segments)."""
        return _label_at(self.labels, self.bounds, progress)


class PreviewStatement(PumaStatement):
    """``puma_command "move LOC"`` and the other one-statement commands, labelled by the
    command as written."""

    problems: tuple[str, ...] = ()

    def __init__(
        self, ctx: Context, allotted: Allotment, statement: Statement, verb: str, written: str
    ) -> None:
        super().__init__(ctx, allotted, statement, verb)
        self.written = written
        self.labels: list[str] = []

    def plan(self, planner: Planner) -> None:
        super().plan(planner)
        self.labels = [self.written] * len(planner.segments)

    def label_at(self, progress: float) -> str:
        return _label_at(self.labels, self.bounds, progress)


def _label_at(labels: list[str], bounds: list[float], progress: float) -> str:
    for label, end in zip(labels, bounds, strict=True):
        if progress <= end + 1e-12:
            return label
    return labels[-1] if labels else ""


def guarded(
    scene: Scene,
    check: Check,
    finger: int | None,
    displacement: tuple[float, float, float],
    travel: float | None,
    frame: str,
) -> Found:
    """A guarded move, stopped at the first touch (see the module's docstring)."""
    d = np.array(displacement, dtype=np.float64)
    length = travel if travel is not None else float(np.linalg.norm(d))
    pos, rot = scene.tool()
    direction = d / np.linalg.norm(d)
    delta = direction if frame == "world" else rot @ direction
    robot, ctx = scene.robot, scene.ctx
    groups = HAND if finger is None else {finger_group(finger)}
    start = pos if finger is None else scene.tip(finger)

    def reach(s: float) -> float:
        """Set the effector toward ``start + delta * s``; how far it stays from there (m)."""
        goal = start + delta * s
        if finger is None:
            robot.arm_target = ctx.arm_ik.track(goal, rot, robot.arm_target, 3)
        else:
            q = ctx.finger_ik.track(finger, goal, robot.arm_target, robot.hand_target, 3)
            robot.hand_target[4 * finger : 4 * finger + 4] = q[4 * finger : 4 * finger + 4]
        scene.pose()
        where = scene.tool()[0] if finger is None else scene.tip(finger)
        return float(np.linalg.norm(where - goal))

    s = 0.0
    while s < length:
        before = scene.save()
        s_next = min(length, s + STEP)
        lag = reach(s_next)
        check()
        if scene.touching(groups, held=False):
            _bisect(scene, before, reach, s, s_next, groups)
            return Found(Outcome.DONE)
        if lag > LAG:
            who = "the tool" if finger is None else f"the {scene.fingers[finger]} fingertip"
            return Found(
                Outcome.MISSED,
                [
                    f"{who} cannot follow the guarded move's line beyond {s * 1000:.0f} mm of "
                    f"{length * 1000:.0f} mm (it stays {lag * 1000:.1f} mm off: a joint limit, "
                    "or out of reach)"
                ],
            )
        s = s_next
    return Found(Outcome.MISSED)


def _bisect(
    scene: Scene,
    free: State,
    reach: Callable[[float], float],
    lo: float,
    hi: float,
    groups: set[int] | frozenset[int],
) -> None:
    """Narrow the first touch down between travels ``lo`` (free) and ``hi``; end touching."""
    touching = scene.save()
    for _ in range(BISECT):
        mid = (lo + hi) / 2
        scene.restore(free)
        reach(mid)
        if scene.touching(groups, held=False):
            hi, touching = mid, scene.save()
        else:
            lo, free = mid, scene.save()
    scene.restore(touching)


def grasp(scene: Scene, check: Check, jmask: int, tmask: int) -> Found:
    """Close the masked joints until each finger touches something or meets its limits."""
    joints = [k for k in range(16) if jmask >> k & 1]
    fingers = sorted({k // 4 for k in joints})
    watched = {k // 4 for k in range(16) if tmask >> k & 1} or set(fingers)
    upper = scene.robot.view.hand_range[:, 1]
    target = scene.robot.hand_target
    stopped: dict[int, set[int]] = {}
    while True:
        closing = [k for k in joints if k // 4 not in stopped and target[k] < upper[k]]
        if not closing:
            break
        target[closing] = np.minimum(target[closing] + CLOSE_STEP, upper[closing])
        scene.pose()
        check()
        for f in fingers:
            if f not in stopped and (touched := scene.touches({finger_group(f)})):
                stopped[f] = touched
    lifted = [scene.carryable(g) for touched in stopped.values() for g in touched]
    bodies = {b for b in lifted if b is not None}
    if bodies:
        scene.hold(bodies, list(stopped))
    return Found(Outcome.DONE if watched <= set(stopped) else Outcome.MISSED)


def sensed(scene: Scene, finger: int | None) -> Outcome:
    """A sensing run's outcome, predicted from the pose (see the module's docstring)."""
    if finger is None:
        return Outcome.DONE
    return Outcome.DONE if scene.touching({finger_group(finger)}) else Outcome.MISSED
