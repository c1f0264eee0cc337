"""A teaching session: the commands of :mod:`dial.teach.commands` on a scene's simulation.

:meth:`Session.execute` runs one command and returns its answer. A command that cannot be
done (a name that does not exist, a goal out of reach, a collision) raises
:class:`TeachError` and leaves the robot and the saved names as they were. Saved names live
in the session until ``write``; ``undo`` goes back to before the last command that moved the
robot or saved a name.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from dial.backend.ik import IKError
from dial.errors import DialError
from dial.geometry import rpy_matrix
from dial.instructions.types import FINGERS
from dial.primitives.arm import Planner
from dial.robot.snapshot import FloatArray
from dial.scene.valii import Appro, Depart, Drive, Move, Statement
from dial.scene.world import JOINTS, World
from dial.teach import report
from dial.teach.commands import (
    Arm,
    Command,
    Ex,
    FingerJoints,
    Jog,
    Limp,
    Pose,
    SaveLocation,
    SavePose,
    Word,
    help_text,
)
from dial.teach.frames import matrix_rpy, relative
from dial.teach.sim import Collision, Pose3, Sim, State
from dial.teach.target import Target, check_name
from dial.teach.worldfile import Taught, location_entry, pose_entry, render, write_world


class TeachError(DialError):
    """A command that could not be done; nothing changed."""


@dataclass(frozen=True)
class Step:
    """What ``undo`` goes back to: the state before a command, and its line."""

    line: str
    state: State
    saved: tuple[Taught, ...]
    world: World
    goal: Pose3


@dataclass(frozen=True)
class Reply:
    text: str
    quit: bool = False


class Session:
    """One scene, its simulation, the names saved so far and the file they go to."""

    def __init__(self, world: World, target: Target, sim: Sim) -> None:
        self.world, self.target, self.sim = world, target, sim
        self.saved: tuple[Taught, ...] = ()
        self.written: tuple[Taught, ...] = ()  # what the target file holds of ours
        self.history: list[Step] = []
        # The tool pose the arm was last sent to. Jogs add to it, and `save location` saves
        # it, so that steps do not drift by the IK's tolerance (0.5 mm) one after another.
        self.goal: Pose3 = sim.start_pose

    # -- state ----------------------------------------------------------------------------------
    @property
    def unsaved(self) -> tuple[Taught, ...]:
        """Names saved in the session that the file does not hold (as saved)."""
        return tuple(e for e in self.saved if e not in self.written)

    def pending_text(self) -> str:
        """The unwritten names as world-file text, so that nothing saved is lost."""
        return render("", self.unsaved).strip("\n")

    def _set_world(self, world: World) -> None:
        self.world = world
        self.sim.ctx.world = world

    # -- dispatch -------------------------------------------------------------------------------
    def execute(self, command: Command, line: str) -> Reply:
        """Run one command; raise :class:`TeachError` when it cannot be done."""
        if isinstance(command, Word):
            return self._word(command)
        before = Step(line, self.sim.state(), self.saved, self.world, self.goal)
        try:
            text = self._do(command)
        except Collision as e:  # the simulation has gone back to before the motion
            raise TeachError(f"refused: {e}; the robot stays where it was") from None
        except IKError as e:
            raise TeachError(f"refused: {e}; the robot stays where it was") from None
        self.history.append(before)
        return Reply(text)

    def _do(self, command: Command) -> str:
        if isinstance(command, Jog):
            return self._jog(command)
        if isinstance(command, Arm):
            return self._arm([(command.statement, command.text)])
        if isinstance(command, Ex):
            program = self.world.programs.get(command.program)
            if program is None:
                raise TeachError(_unknown("program", command.program, self.world.programs))
            where = f"program {program.name}, line"
            return self._arm([(st, f"{where} {st.line}") for st in program.statements])
        if isinstance(command, FingerJoints):
            return self._finger(command)
        if isinstance(command, Limp):
            self.sim.go_limp(command.mask, command.seconds)
            return report.hand(self.sim.hand_q(), command.mask)
        if isinstance(command, Pose):
            return self._pose(command)
        if isinstance(command, SavePose):
            return self._save_pose(command)
        assert isinstance(command, SaveLocation)
        return self._save_location(command)

    def _word(self, command: Word) -> Reply:
        verb = command.verb
        if verb == "help":
            try:
                return Reply(help_text(command.arg))
            except DialError as e:
                raise TeachError(str(e)) from None
        if verb == "where":
            return Reply(report.where(self.sim, self.goal))
        if verb == "names":
            return Reply(report.names(self.world, {e.name for e in self.saved}))
        if verb == "undo":
            return Reply(self._undo())
        if verb == "write":
            return Reply(self.write())
        if verb == "quit" and self.unsaved:
            raise TeachError(
                f"{_count(self.unsaved)} not written to {self.target.path.name}: "
                "'write' them, or 'quit!' to drop them"
            )
        return Reply("bye", quit=True)

    # -- arm ------------------------------------------------------------------------------------
    def _jog(self, jog: Jog) -> str:
        p0, r0 = self.goal
        d, turn = np.array(jog.delta), rpy_matrix(jog.turn)
        if jog.frame == "tool":
            p1, r1 = p0 + r0 @ d, r0 @ turn
        else:
            p1, r1 = p0 + d, turn @ r0
        planner = Planner(self.sim.ctx, self.sim.arm_target)
        planner.line_to(p1, r1, "the jog's goal")
        self.sim.move_arm(planner.segments)
        self.goal = (p1, r1)
        return report.tool(self.sim, self.goal)

    def _arm(self, statements: list[tuple[Statement, str]]) -> str:
        planner = Planner(self.sim.ctx, self.sim.arm_target)
        goal = self.goal
        for st, where in statements:
            if isinstance(st, Move | Appro) and st.location not in self.world.locations:
                raise TeachError(_unknown("location", st.location, self.world.locations))
            if isinstance(st, Drive):  # `dial run` stops a DRIVE at the limit; teaching refuses
                self._check_drive(st, planner.q)
            planner.statement(st, where)
            goal = self._statement_goal(st, goal, planner)
        self.sim.move_arm(planner.segments)
        self.goal = goal
        return report.tool(self.sim, self.goal)

    def _check_drive(self, st: Drive, q: FloatArray) -> None:
        j = st.joint - 1
        arm = self.sim.index.profile.arm.name
        if j >= len(q):
            raise TeachError(f"refused: the {arm} has joints 1 to {len(q)}, not {st.joint}")
        lo, hi = self.sim.arm_range[j]
        goal = q[j] + st.angle
        if not lo <= goal <= hi:
            raise TeachError(
                f"refused: {arm} joint {st.joint} would go to {math.degrees(goal):.1f} deg, beyond "
                f"its range {math.degrees(lo):.0f} to {math.degrees(hi):.0f} deg; the robot "
                "stays where it was"
            )

    def _statement_goal(self, st: Statement, goal: Pose3, planner: Planner) -> Pose3:
        """The tool pose a statement sends the arm to, as commanded (not as IK reached it)."""
        if isinstance(st, Move | Appro):
            pos, rot = self.sim.ctx.location(st.location)
            back = st.distance if isinstance(st, Appro) else 0.0
            return pos - back * rot[:, 2], rot
        if isinstance(st, Depart):
            return goal[0] - st.distance * goal[1][:, 2], goal[1]
        return self.sim.ik.fk(planner.q)

    # -- hand -----------------------------------------------------------------------------------
    def _hand_goal(self, joints: Mapping[int, float], mask: int) -> str:
        goal = np.where(self.sim.limp, self.sim.hand_q(), self.sim.hand_target)
        lo, hi = self.sim.hand_range[:, 0], self.sim.hand_range[:, 1]
        for bit, angle in joints.items():
            if not lo[bit] - 1e-9 <= angle <= hi[bit] + 1e-9:
                name = f"{FINGERS[bit // 4]} {JOINTS[bit % 4]}"
                raise TeachError(
                    f"{name} would go to {math.degrees(angle):.1f} deg, beyond its range "
                    f"{math.degrees(lo[bit]):.0f} to {math.degrees(hi[bit]):.0f} deg"
                )
            goal[bit] = angle
        self.sim.move_hand(goal, mask)
        return report.hand(self.sim.hand_q(), mask)

    def _finger(self, command: FingerJoints) -> str:
        base = np.where(self.sim.limp, self.sim.hand_q(), self.sim.hand_target)
        bits = [4 * command.finger + j for j in command.joints]
        angles = {
            bit: (base[bit] if command.relative else 0.0) + a
            for bit, a in zip(bits, command.angles, strict=True)
        }
        return self._hand_goal(angles, sum(1 << b for b in bits))

    def _pose(self, command: Pose) -> str:
        pose = self.world.poses.get(command.name)
        if pose is None:
            raise TeachError(_unknown("pose", command.name, self.world.poses))
        mask = pose.mask & command.mask
        if not mask:
            raise TeachError(f"pose '{pose.name}' sets none of the joints of that mask")
        return self._hand_goal({b: a for b, a in pose.angles.items() if mask >> b & 1}, mask)

    # -- saving ---------------------------------------------------------------------------------
    def _save(self, entry: Taught, note: str, world: World) -> str:
        key = (entry.table, entry.name)
        self.saved = (*(e for e in self.saved if (e.table, e.name) != key), entry)
        self._set_world(world)
        return f"saved {entry.text().rstrip()}{note}\n(not written yet: 'write' writes it)"

    def _save_pose(self, command: SavePose) -> str:
        note = check_name(self.target, self.saved, "poses", command.name, command.replace)
        q = self.sim.hand_q()
        angles = {b: math.degrees(q[b]) for b in range(16) if command.mask >> b & 1}
        pose, entry = pose_entry(command.name, angles)
        poses = MappingProxyType({**self.world.poses, pose.name: pose})
        return self._save(entry, note, dataclasses.replace(self.world, poses=poses))

    def _save_location(self, command: SaveLocation) -> str:
        note = check_name(self.target, self.saved, "locations", command.name, command.replace)
        pos, rot = self.goal  # as commanded: what a script's IK will aim at
        body = None
        if command.obj is not None:
            body = self.world.objects.get(command.obj)
            if body is None:
                raise TeachError(_unknown("object", command.obj, self.world.objects))
            frame_pos, frame_rot = self.sim.body_pose(body)  # where it is now, not at load
            pos, rot = relative(pos, rot, frame_pos, frame_rot, command.world_axes)
        loc, entry = location_entry(
            command.name, command.obj, body, pos, matrix_rpy(rot), command.world_axes
        )
        locations = MappingProxyType({**self.world.locations, loc.name: loc})
        return self._save(entry, note, dataclasses.replace(self.world, locations=locations))

    def _undo(self) -> str:
        if not self.history:
            raise TeachError("nothing to undo")
        step = self.history.pop()
        self.sim.restore(step.state)
        self.saved = step.saved
        self._set_world(step.world)
        self.goal = step.goal
        return f"undid '{step.line}'"

    def write(self) -> str:
        """Write the saved names into the target file (atomically, with a backup)."""
        path = self.target.path
        if self.saved == self.written:
            return f"nothing to write: {path} is unchanged"
        text = render(self.target.text, self.saved)
        backup = write_world(path, text)
        self.written = self.saved
        names = ", ".join(e.name for e in self.saved)
        kept = f"; the previous file is {backup}" if backup else ""
        return f"wrote {names} to {path}{kept}"


def _count(entries: tuple[Taught, ...]) -> str:
    names = ", ".join(e.name for e in entries)
    return f"{len(entries)} saved name{'s' if len(entries) != 1 else ''} ({names})"


def _unknown(kind: str, name: str, valid: Mapping[str, object]) -> str:
    return f"unknown {kind} '{name}'; {kind}s: {', '.join(valid) or '(none)'}"
