"""Arm motion: VAL-II programs and commands (puma_command) and relative moves (arm_move).

A motion is planned at its start as segments (joint-interpolated or straight
line) and time-scaled over the run's executing ticks in tick time. A straight
line is solved at its start as IK waypoints a few mm apart, each warm-started
from the one before; the arm moves between them in joint space. So the IK cost
of a line depends on its length, not on its duration (a slow tick would
otherwise solve one waypoint per control period).
"""

from __future__ import annotations

import math
from abc import abstractmethod
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from dial.geometry import Slerp, rpy_matrix, smooth, smooth_array
from dial.primitives.context import Context, RobotPrimitive
from dial.robot.memo import recall, remember
from dial.robot.protocol import Course
from dial.robot.slots import still
from dial.robot.snapshot import FloatArray, Snapshot
from dial.scene.valii import Appro, Depart, Drive, Move, Statement
from dial.scheduler.primitive import DONE, Allotment, Ended, Now, Outcome, progress_after

JOINT_SPEED = 1.0  # rad/s: nominal, only to share a run's time among its segments
LINEAR_SPEED = 0.25  # m/s
TURN_SPEED = 1.0  # rad/s
# Waypoint spacing on a straight line. Between two waypoints the tool leaves the line by
# about (step^2 / 8) times the path's curvature in joint space: micrometres here, well below
# the IK tolerance (0.5 mm).
LINE_STEP = 0.004  # m
LINE_TURN_STEP = np.radians(2.0)  # rad


@dataclass(frozen=True)
class Segment:
    """One piece of an arm motion: joint-interpolated, or a straight tool line.

    ``waypoints`` (N + 1, arm joints): a line's joint configurations at u = k / N along it, from its
    start to its goal; two rows (its ends) for a joint-interpolated segment.
    """

    waypoints: FloatArray
    cost: float

    @property
    def q1(self) -> FloatArray:
        """The goal configuration, as IK solved it."""
        goal: FloatArray = self.waypoints[-1]
        return goal

    def at(self, u: float) -> FloatArray:
        """The configuration at fraction ``u`` in [0, 1] of the segment."""
        last = len(self.waypoints) - 1
        x = min(1.0, max(0.0, u)) * last
        if x >= last:  # exactly the goal (a + (b - a) * 1 may be a bit off)
            return self.q1.copy()
        k = int(x)
        out: FloatArray = self.waypoints[k] + self.steps[k] * (x - k)
        return out

    @cached_property
    def steps(self) -> FloatArray:
        """(N, arm joints): each waypoint's difference to the next (b - a, worked out once)."""
        steps: FloatArray = self.waypoints[1:] - self.waypoints[:-1]
        return steps

    def at_array(self, u: FloatArray) -> FloatArray:
        """(K, arm joints): :meth:`at` of each fraction, bit for bit."""
        last = len(self.waypoints) - 1
        x = np.minimum(1.0, np.maximum(0.0, u)) * last
        k = np.minimum(x.astype(np.intp), last - 1)
        out: FloatArray = self.waypoints[k] + self.steps[k] * (x - k)[:, None]
        out[x >= last] = self.q1
        return out


class Planner:
    """Turns statements into segments, from a start configuration."""

    def __init__(self, ctx: Context, q: FloatArray) -> None:
        self.ctx, self.q = ctx, np.array(q, dtype=np.float64)
        self.segments: list[Segment] = []
        self.warnings: list[str] = []

    def joint_to(self, q1: FloatArray) -> None:
        cost = float(np.abs(q1 - self.q).max()) / JOINT_SPEED
        self.segments.append(Segment(np.stack([self.q, q1]), cost))
        self.q = q1

    def line_to(self, p1: FloatArray, r1: FloatArray, what: str) -> None:
        """A straight tool line to the pose, as IK waypoints. A line depends only on its
        start and goal (the solves are deterministic), so a line planned before in this
        process (a sweep's trials, a loop's passes) is taken whole from the IK's memo."""
        # Under the IK's own name: the preview's IK (dial.preview.ik) answers to rounding only.
        key, known = recall(f"{self.ctx.arm_ik.MEMO}-line", self.q, p1, r1)
        if not isinstance(known, Segment):
            self._line(p1, r1, what)
            known = self.segments.pop()
            known.waypoints.flags.writeable = False  # shared by every run that plans it
            remember(key, known)
        self.segments.append(known)
        self.q = known.q1

    def _line(self, p1: FloatArray, r1: FloatArray, what: str) -> None:
        ik = self.ctx.arm_ik
        p0, r0 = ik.fk(self.q)
        q1 = ik.solve(p1, r1, self.q, what)
        length = float(np.linalg.norm(p1 - p0))
        turn = float(np.arccos(np.clip((np.trace(r0.T @ r1) - 1.0) / 2.0, -1.0, 1.0)))
        n = max(1, math.ceil(max(length / LINE_STEP, turn / LINE_TURN_STEP)))
        waypoints, turning = [self.q], Slerp(r0, r1)
        q0 = self.q
        for k in range(1, n):
            u = k / n
            # A redundant arm's goal, solved from afar, may hold its spare freedom elsewhere
            # than the start (its posture task): the waypoints are drawn to the joints'
            # interpolation, so that it moves evenly along the line, not in its last step.
            guide = q0 + (q1 - q0) * u
            waypoints.append(ik.track(p0 + (p1 - p0) * u, turning(u), waypoints[-1], guide=guide))
        waypoints.append(q1)
        cost = max(length / LINEAR_SPEED, turn / TURN_SPEED)
        self.segments.append(Segment(np.stack(waypoints), cost))
        self.q = q1

    def statement(self, st: Statement, where: str) -> None:
        ik = self.ctx.arm_ik
        match st:
            case Move(location=location, straight=True):
                pos, rot = self.ctx.location(location)
                self.line_to(pos, rot, f"location '{location}' ({where})")
            case Move(location=location):
                pos, rot = self.ctx.location(location)
                self.joint_to(ik.solve(pos, rot, self.q, f"location '{location}' ({where})"))
            case Appro(location=location, distance=distance):
                pos, rot = self.ctx.location(location)
                pos = pos - distance * rot[:, 2]
                self.joint_to(ik.solve(pos, rot, self.q, f"APPRO {location} ({where})"))
            case Depart(distance=distance):
                p0, r0 = ik.fk(self.q)
                self.line_to(p0 - distance * r0[:, 2], r0, f"DEPART ({where})")
            case Drive():
                self.joint_to(self.drive(st, where))

    def drive(self, st: Drive, where: str) -> FloatArray:
        """DRIVE: one joint by an angle, stopped at the joint's limit with a warning."""
        q1 = self.q.copy()
        j = st.joint - 1
        lo, hi = self.ctx.view.arm_range[j]
        goal = q1[j] + st.angle
        q1[j] = min(hi, max(lo, goal))
        if q1[j] != goal:
            side, limit = ("upper", hi) if goal > hi else ("lower", lo)
            self.warnings.append(
                f"DRIVE {st.joint} {np.degrees(st.angle):g} ({where}): the target "
                f"{np.degrees(goal):.1f} deg is {np.degrees(abs(goal - limit)):.1f} deg beyond "
                f"joint {st.joint}'s {side} limit ({np.degrees(limit):.1f} deg); it stops there"
            )
        return q1


class ArmMotion(RobotPrimitive):
    """Follows planned segments over the run's progress (tick time)."""

    def __init__(self, ctx: Context, allotted: Allotment) -> None:
        super().__init__(ctx, allotted)
        self.segments: list[Segment] = []
        self.bounds: list[float] = []
        self.warnings: tuple[str, ...] = ()

    @abstractmethod
    def plan(self, planner: Planner) -> None:
        """Add this run's segments to ``planner``."""

    def start(self, snapshot: Snapshot) -> None:
        planner = Planner(self.ctx, snapshot.arm_target)
        self.plan(planner)
        self.segments = planner.segments
        self.warnings = tuple(planner.warnings)
        total = sum(s.cost for s in self.segments)
        acc, self.bounds = 0.0, []
        for s in self.segments:
            acc += s.cost / total if total > 0 else 1.0 / len(self.segments)
            self.bounds.append(acc)
        self._ends = np.array(self.bounds)  # for course: each segment's end and start
        self._starts = np.concatenate(([0.0], self._ends[:-1]))
        self._table: FloatArray | None = None  # course's set-points, made at its first call
        self.q = snapshot.arm_target.copy()

    def step(self, snapshot: Snapshot, now: Now) -> Ended | None:
        if not self.segments:
            return None
        start = 0.0
        for seg, end in zip(self.segments, self.bounds, strict=True):
            if now.progress <= end + 1e-12 or seg is self.segments[-1]:
                self.q = seg.at(smooth((now.progress - start) / max(end - start, 1e-12)))
                break
            start = end
        self.slots.arm(self.q)
        return None

    open_loop = True

    def course(self, first: int, count: int) -> Course:
        """The set-points :meth:`step` would write in these periods: those of all the run's
        periods are computed once, as one array, and a course is a slice of it."""
        if not self.segments:
            return still
        span, n = self.allotted.span, self.allotted.periods_per_tick
        if self._table is None:
            progress = [progress_after(k, span, n) for k in range(1, span + 1)]
            self._table = self._rows(np.array(progress))
            self._table.flags.writeable = False
        if first >= 1 and first + count - 1 <= span:
            return self.slots.arm_course(self._table[first - 1 : first - 1 + count])
        beyond = [progress_after(k, span, n) for k in range(first, first + count)]
        return self.slots.arm_course(self._rows(np.array(beyond)))

    def _rows(self, p: FloatArray) -> FloatArray:
        """(len(p), arm joints): :meth:`step`'s set-points at each progress in ``p``, bit for
        bit."""
        if len(self.segments) == 1:
            return self.segments[0].at_array(smooth_array(p / max(self.bounds[0], 1e-12)))
        ends = self._ends
        # The first segment whose end (+1e-12) the progress has not passed, as step's loop.
        which = np.minimum(np.searchsorted(ends + 1e-12, p, side="left"), len(ends) - 1)
        starts = self._starts[which]
        u = smooth_array((p - starts) / np.maximum(ends[which] - starts, 1e-12))
        rows = np.empty((len(p), len(self.q)))
        for j in range(int(which[0]), int(which[-1]) + 1):  # progress only grows
            rows[which == j] = self.segments[j].at_array(u[which == j])
        return rows

    def finish(self, snapshot: Snapshot) -> Ended:
        return Ended(Outcome.DONE, warnings=self.warnings) if self.warnings else DONE


class PumaProgram(ArmMotion):
    """``puma_command "ex PROG"``: the world file's stored program ``program``."""

    def __init__(self, ctx: Context, allotted: Allotment, program: str) -> None:
        super().__init__(ctx, allotted)
        self.program = program

    def plan(self, planner: Planner) -> None:
        name = self.program
        for stored in self.ctx.world.programs[name].statements:
            planner.statement(stored, f"program {name}, line {stored.line}")


class PumaStatement(ArmMotion):
    """``puma_command "move LOC"`` (or moves, appro, depart, drive): one VAL-II statement;
    ``verb`` names it in messages."""

    def __init__(self, ctx: Context, allotted: Allotment, statement: Statement, verb: str) -> None:
        super().__init__(ctx, allotted)
        self.statement, self.verb = statement, verb

    def plan(self, planner: Planner) -> None:
        planner.statement(self.statement, self.verb)


class ArmMove(ArmMotion):
    """``arm_move DX DY DZ [RX RY RZ] [frame=tool|world]``: a relative straight line of
    ``displacement`` (m) and ``rotation`` (roll, pitch, yaw in rad) in ``frame``."""

    def __init__(
        self,
        ctx: Context,
        allotted: Allotment,
        displacement: tuple[float, float, float],
        rotation: tuple[float, float, float],
        frame: str,
    ) -> None:
        super().__init__(ctx, allotted)
        self.displacement, self.rotation, self.frame = displacement, rotation, frame

    def plan(self, planner: Planner) -> None:
        p0, r0 = self.ctx.arm_ik.fk(planner.q)
        d = np.array(self.displacement, dtype=np.float64)
        turn = rpy_matrix(self.rotation)
        if self.frame == "tool":
            p1, r1 = p0 + r0 @ d, r0 @ turn
        else:
            p1, r1 = p0 + d, turn @ r0
        planner.line_to(p1, r1, "the arm_move goal")
