"""Inverse kinematics with mink on a robot-only copy of the model.

The IK model holds only the arm and hand (no scene objects), so its QP stays at the robot's
velocities (22 for the Utah hand on the PUMA) whatever the scene holds. Solutions are
warm-started from the last one: a straight-line move solves one waypoint per control
period. The tool site, the task weights, a posture task for a redundant arm and the retry
seeds are the robot profile's (``[arm.ik]`` of its ``robot.toml``).

Every solution is memoized by its exact inputs (:mod:`dial.robot.memo`, also kept in the
user's cache folder, in a file named after the model, the profile and the solver's code),
and mink is imported, and its tasks set up, only when a solver first meets a problem that
the memo does not hold: a run whose solves are all known never loads mink, qpsolvers or
SciPy. Forward kinematics needs only MuJoCo.
"""

from __future__ import annotations

import sys
from functools import cached_property
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from dial.backend.fingerprint import fingerprint
from dial.backend.index import RobotIndex
from dial.backend.model import default_profile, load_model
from dial.errors import DialError
from dial.robot.memo import memo_for, memo_key
from dial.robot.snapshot import FloatArray
from dial.robots.profile import RobotProfile

if TYPE_CHECKING:
    import mink

SOLVER = "daqp"
DT = 0.01  # s: the differential step of one solve
POS_TOL = 5e-4  # m
ROT_TOL = 2e-3  # rad
SOLVE_ITERATIONS = 200  # per start of ArmIK.solve
DAMPING = 1e-3  # mink's Levenberg-Marquardt damping of every step
NEAR = 20.0  # within this many tolerances of the target, the posture task is left out


class IKError(DialError):
    """A target the arm or a finger cannot reach; the message says how far off it stays."""


class _Base:
    def __init__(
        self, model: mujoco.MjModel | None = None, profile: RobotProfile | None = None
    ) -> None:
        """On the robot-only model of ``profile`` (the default robot when None), compiled, or
        ``model`` (one; for several solvers)."""
        profile = default_profile() if profile is None else profile
        self.model = load_model(profile=profile) if model is None else model
        self.index = RobotIndex.from_model(self.model, profile)
        self.robot = profile.name  # in the memo's keys: two robots may share a configuration
        # The memo's file is named after the model, the profile (its IK settings are not in
        # the model) and the solvers' code: this module and the solver class's own.
        code = {
            getattr(sys.modules[c.__module__], "__file__", None)
            for c in type(self).__mro__
            if c.__module__.startswith("dial.")
        }
        sources = [f for f in code if f is not None] + [str(profile.path)]
        self.memo = memo_for(fingerprint(self.model, sources))
        self._kinematics = mujoco.MjData(self.model)  # for fk, apart from mink's

    @cached_property
    def start(self) -> FloatArray:
        """The model's reference configuration, with joints whose 0 is out of their range
        (the Allegro's thumb base) at the nearest limit: a configuration outside the limits
        has no feasible step."""
        q: FloatArray = self.model.qpos0.copy()
        limited = self.model.jnt_limited.astype(bool)
        adr = self.model.jnt_qposadr[limited]
        q[adr] = np.clip(q[adr], self.model.jnt_range[limited, 0], self.model.jnt_range[limited, 1])
        return q

    @cached_property
    def config(self) -> mink.Configuration:
        """mink's configuration, made when the first solve needs it."""
        import mink  # a run whose solves are all memoized never loads it

        return mink.Configuration(self.model, self.start)

    @cached_property
    def limits(self) -> list[mink.ConfigurationLimit]:
        import mink

        return [mink.ConfigurationLimit(self.model)]

    def _site(self, name: str) -> int:
        return int(mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, name))


class ArmIK(_Base):
    """Tool-frame IK over the arm's joints (with a posture task for the spare freedom of an
    arm of more than six)."""

    def __init__(
        self, model: mujoco.MjModel | None = None, profile: RobotProfile | None = None
    ) -> None:
        super().__init__(model, profile)
        self.MEMO = f"arm:{self.robot}"  # the memo's name for this solver's results
        self.settings = self.index.profile.arm.ik
        self.redundant = self.settings.posture_cost > 0  # a posture task for the spare freedom
        self.seeds = tuple(np.array(s, dtype=np.float64) for s in self.settings.seeds)

    @cached_property
    def task(self) -> mink.FrameTask:
        import mink

        return mink.FrameTask(
            self.index.profile.arm.tool_site,
            "site",
            position_cost=self.settings.position_cost,
            orientation_cost=self.settings.orientation_cost,
        )

    @cached_property
    def rest(self) -> FloatArray:
        """The posture task's target: the profile's arm posture, the hand at its start."""
        target = self.start.copy()
        target[self.index.arm_qpos] = self.settings.posture
        return target

    @cached_property
    def posture(self) -> mink.PostureTask | None:
        if not self.redundant:
            return None
        import mink

        cost = np.zeros(self.model.nv)
        cost[self.index.arm_dof] = self.settings.posture_cost
        posture = mink.PostureTask(self.model, cost=cost)
        posture.set_target(self.rest)
        return posture

    @cached_property
    def tasks(self) -> list[mink.Task]:
        return [self.task] if self.posture is None else [self.task, self.posture]

    @cached_property
    def constraints(self) -> list[mink.DofFreezingTask]:
        import mink

        hand = [int(d) for d in self.index.hand_dof]
        return [mink.DofFreezingTask(self.model, dof_indices=hand)]

    def fk(self, arm_q: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Tool position (3,) and rotation (3, 3) at ``arm_q`` (the hand at rest, as in
        mink's configuration, whose hand joints no solve moves)."""
        d = self._kinematics
        d.qpos[self.index.arm_qpos] = arm_q
        mujoco.mj_kinematics(self.model, d)
        site = self.index.tool_site
        return d.site_xpos[site].copy(), d.site_xmat[site].reshape(3, 3).copy()

    def _set(self, arm_q: FloatArray) -> None:
        q = self.config.q.copy()
        q[self.index.arm_qpos] = arm_q
        self.config.update(q)

    def _iterate(
        self, pos: FloatArray, rot: FloatArray, iterations: int, posture: bool = False
    ) -> tuple[float, float]:
        import mink

        target = mink.SE3.from_rotation_and_translation(mink.SO3.from_matrix(rot), pos)
        self.task.set_target(target)
        perr = rerr = np.inf
        for _ in range(iterations):
            err = self.task.compute_error(self.config)
            perr, rerr = float(np.linalg.norm(err[:3])), float(np.linalg.norm(err[3:]))
            if perr < POS_TOL and rerr < ROT_TOL:
                break
            # A posture task (a redundant arm) chooses the basin from afar; near the target
            # it would pull the tool off it, so the last steps are the frame task's alone.
            near = not posture and perr < NEAR * POS_TOL and rerr < NEAR * ROT_TOL
            vel = mink.solve_ik(
                self.config,
                self.tasks[:1] if near else self.tasks,
                DT,
                SOLVER,
                damping=DAMPING,
                limits=self.limits,
                constraints=self.constraints,
            )
            self.config.integrate_inplace(vel, DT)
        return perr, rerr

    def track(
        self,
        pos: FloatArray,
        rot: FloatArray,
        arm_q: FloatArray,
        iterations: int = 2,
        guide: FloatArray | None = None,
    ) -> FloatArray:
        """A few warm-started steps from ``arm_q`` toward the pose: one waypoint of a line.

        ``guide``: where a redundant arm's spare freedom is drawn (its posture task stays on
        and aims there, not at the posture): a line's joint interpolation from its start to
        its goal, so that the spare freedom moves evenly along the line rather than at its
        end. An arm without a posture task ignores it."""
        if not self.redundant:
            guide = None
        guided = () if guide is None else (guide,)  # a key's parts are what its file keeps
        key = memo_key(f"{self.MEMO}-track", pos, rot, arm_q, iterations, *guided)
        known = self.memo.get(key)
        if isinstance(known, np.ndarray):
            return known.copy()
        self._set(arm_q)
        if guide is None or self.posture is None:
            self._iterate(pos, rot, iterations)
        else:
            target = self.rest.copy()
            target[self.index.arm_qpos] = guide
            self.posture.set_target(target)
            self._iterate(pos, rot, iterations, posture=True)
            self.posture.set_target(self.rest)
            self._iterate(pos, rot, iterations)  # then back onto the line, the frame task alone
        q: FloatArray = self.config.q[self.index.arm_qpos].copy()
        self.memo.put(key, q.copy())
        return q

    def solve(self, pos: FloatArray, rot: FloatArray, arm_q: FloatArray, what: str) -> FloatArray:
        """Converge on the pose; raise :class:`IKError` if it is out of reach.

        Differential IK from ``arm_q`` finds the solution in its own basin, which is the one
        to keep (no wrist flip). It can stall against a joint limit far from the goal; then
        fixed wrist and elbow variations of the start are tried in order, and the first that
        converges wins. Deterministic.
        """
        start = np.asarray(arm_q, dtype=np.float64)
        key = memo_key(f"{self.MEMO}-solve", pos, rot, start)
        known = self.memo.get(key)
        closest = known if isinstance(known, tuple) else (np.inf, np.inf)
        if isinstance(known, np.ndarray):
            return known.copy()
        for offset in self.seeds if known is None else ():
            self._set(start + offset)
            perr, rerr = self._iterate(pos, rot, SOLVE_ITERATIONS)
            if perr <= 2e-3 and rerr <= 1e-2:
                q: FloatArray = self.config.q[self.index.arm_qpos].copy()
                self.memo.put(key, q.copy())
                return q
            closest = min(closest, (perr, rerr))
        self.memo.put(key, closest)
        raise IKError(
            f"{what} is out of the arm's reach: the tool stays {closest[0] * 1000:.1f} mm "
            f"and {np.degrees(closest[1]):.1f} deg away"
        )


class FingerIK(_Base):
    """Fingertip-position IK over one finger's joints, the rest of the robot frozen."""

    @cached_property
    def tasks(self) -> list[mink.FrameTask]:
        import mink

        return [
            mink.FrameTask(f.tip_site, "site", position_cost=1.0, orientation_cost=0.0)
            for f in self.index.profile.fingers
        ]

    @cached_property
    def constraints(self) -> list[mink.DofFreezingTask]:
        import mink

        ix = self.index
        bits = ix.hand_bits.tolist()
        constraints = []
        for f in range(len(ix.profile.fingers)):
            free = {int(ix.hand_dof[i]) for i, b in enumerate(bits) if b // 4 == f}
            frozen = [d for d in range(self.model.nv) if d not in free]
            constraints.append(mink.DofFreezingTask(self.model, dof_indices=frozen))
        return constraints

    def tip(self, arm_q: FloatArray, hand_q: FloatArray, finger: int) -> FloatArray:
        d = self._kinematics
        d.qpos[self.index.arm_qpos] = arm_q
        d.qpos[self.index.hand_qpos] = np.asarray(hand_q)[self.index.hand_bits]
        mujoco.mj_kinematics(self.model, d)
        tip: FloatArray = d.site_xpos[self.index.fingertip_sites[finger]].copy()
        return tip

    def _set(self, arm_q: FloatArray, hand_q: FloatArray) -> None:
        q = self.config.q.copy()
        q[self.index.arm_qpos] = arm_q
        q[self.index.hand_qpos] = hand_q[self.index.hand_bits]
        self.config.update(q)

    def track(
        self,
        finger: int,
        tip: FloatArray,
        arm_q: FloatArray,
        hand_q: FloatArray,
        iterations: int = 2,
    ) -> FloatArray:
        """Steps from ``hand_q`` moving the fingertip toward ``tip`` (world, m); returns (16,)."""
        key = memo_key(f"finger-track-{self.robot}", int(finger), tip, arm_q, hand_q, iterations)
        known = self.memo.get(key)
        if isinstance(known, np.ndarray):
            return known.copy()
        import mink

        self._set(arm_q, hand_q)
        task = self.tasks[finger]
        # Position only: keep the tip's own orientation in the target, since mink's frame error
        # mixes rotation into the translation part when the two disagree.
        site = self.index.fingertip_sites[finger]
        rot = mink.SO3.from_matrix(self.config.data.site_xmat[site].reshape(3, 3))
        task.set_target(
            mink.SE3.from_rotation_and_translation(rot, np.asarray(tip, dtype=np.float64))
        )
        for _ in range(iterations):
            if np.linalg.norm(task.compute_error(self.config)[:3]) < POS_TOL / 5:
                break
            vel = mink.solve_ik(
                self.config,
                [task],
                DT,
                SOLVER,
                damping=DAMPING,
                limits=self.limits,
                constraints=[self.constraints[finger]],
            )
            self.config.integrate_inplace(vel, DT)
        q: FloatArray = np.asarray(hand_q, dtype=np.float64).copy()
        q[self.index.hand_bits] = self.config.q[self.index.hand_qpos]
        self.memo.put(key, q.copy())
        return q
