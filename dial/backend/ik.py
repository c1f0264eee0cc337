"""Inverse kinematics with mink on a robot-only copy of the model.

The IK model holds only the arm and hand (no scene objects), so its QP stays at
22 velocities whatever the scene holds. Solutions are warm-started from the last
one: a straight-line move solves one waypoint per control period.

Every solution is memoized by its exact inputs (:mod:`dial.robot.memo`, also kept in the
user's cache folder), and mink is imported, and its tasks set up, only when a solver first
meets a problem that the memo does not hold: a run whose solves are all known never loads
mink, qpsolvers or SciPy. Forward kinematics needs only MuJoCo.
"""

from __future__ import annotations

import sys
from functools import cached_property
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from dial.backend.fingerprint import fingerprint
from dial.backend.model import RobotIndex, load_model
from dial.errors import DialError
from dial.robot.memo import memo_for, memo_key
from dial.robot.snapshot import FloatArray

if TYPE_CHECKING:
    import mink

SOLVER = "daqp"
DT = 0.01  # s: the differential step of one solve
POS_TOL = 5e-4  # m
ROT_TOL = 2e-3  # rad
SOLVE_ITERATIONS = 200  # per start of ArmIK.solve
DAMPING = 1e-3  # mink's Levenberg-Marquardt damping of every step


class IKError(DialError):
    """A target the arm or a finger cannot reach; the message says how far off it stays."""


class _Base:
    def __init__(self, model: mujoco.MjModel | None = None) -> None:
        """On the robot-only model, compiled, or ``model`` (one; for several solvers)."""
        self.model = load_model() if model is None else model
        self.index = RobotIndex.from_model(self.model)
        # The solvers' code: this module and the solver class's own (a subclass may solve
        # differently); the memo's file is named after it and the model.
        code = {
            getattr(sys.modules[c.__module__], "__file__", None)
            for c in type(self).__mro__
            if c.__module__.startswith("dial.")
        }
        self.memo = memo_for(fingerprint(self.model, [f for f in code if f is not None]))
        self._kinematics = mujoco.MjData(self.model)  # for fk, apart from mink's

    @cached_property
    def config(self) -> mink.Configuration:
        """mink's configuration, made when the first solve needs it."""
        import mink  # a run whose solves are all memoized never loads it

        return mink.Configuration(self.model)

    @cached_property
    def limits(self) -> list[mink.ConfigurationLimit]:
        import mink

        return [mink.ConfigurationLimit(self.model)]

    def _site(self, name: str) -> int:
        return int(mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, name))


class ArmIK(_Base):
    """Tool-frame (``hand_palm``) IK over the six PUMA joints."""

    MEMO = "arm"  # the memo's name for this solver's results

    @cached_property
    def task(self) -> mink.FrameTask:
        import mink

        return mink.FrameTask("hand_palm", "site", position_cost=1.0, orientation_cost=0.2)

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

    def _iterate(self, pos: FloatArray, rot: FloatArray, iterations: int) -> tuple[float, float]:
        import mink

        target = mink.SE3.from_rotation_and_translation(mink.SO3.from_matrix(rot), pos)
        self.task.set_target(target)
        perr = rerr = np.inf
        for _ in range(iterations):
            err = self.task.compute_error(self.config)
            perr, rerr = float(np.linalg.norm(err[:3])), float(np.linalg.norm(err[3:]))
            if perr < POS_TOL and rerr < ROT_TOL:
                break
            vel = mink.solve_ik(
                self.config,
                [self.task],
                DT,
                SOLVER,
                damping=DAMPING,
                limits=self.limits,
                constraints=self.constraints,
            )
            self.config.integrate_inplace(vel, DT)
        return perr, rerr

    def track(
        self, pos: FloatArray, rot: FloatArray, arm_q: FloatArray, iterations: int = 2
    ) -> FloatArray:
        """A few warm-started steps from ``arm_q`` toward the pose: one waypoint of a line."""
        key = memo_key(f"{self.MEMO}-track", pos, rot, arm_q, iterations)
        known = self.memo.get(key)
        if isinstance(known, np.ndarray):
            return known.copy()
        self._set(arm_q)
        self._iterate(pos, rot, iterations)
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
        for offset in _SEEDS if known is None else ():
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


# Start offsets for ArmIK.solve: as given, then wrist (joints 4 and 6) and elbow variations.
_SEEDS: tuple[FloatArray, ...] = tuple(
    np.array(o, dtype=np.float64)
    for o in (
        (0, 0, 0, 0, 0, 0),
        (0, 0, 0, np.pi / 2, 0, -np.pi / 2),
        (0, 0, 0, -np.pi / 2, 0, np.pi / 2),
        (0, 0, 0, 0, 0, np.pi),
        (0, 0, 0, 0, 0, -np.pi),
        (0, -0.5, 0.5, 0, 0.5, 0),
        (0, 0.5, -0.5, 0, -0.5, 0),
    )
)


class FingerIK(_Base):
    """Fingertip-position IK over one finger's four joints, the rest of the robot frozen."""

    @cached_property
    def tasks(self) -> list[mink.FrameTask]:
        import mink

        return [
            mink.FrameTask(f"hand_{f}_tip", "site", position_cost=1.0, orientation_cost=0.0)
            for f in ("index", "middle", "ring", "thumb")
        ]

    @cached_property
    def constraints(self) -> list[mink.DofFreezingTask]:
        import mink

        constraints = []
        for f in range(4):
            free = {int(d) for d in self.index.hand_dof[4 * f : 4 * f + 4]}
            frozen = [d for d in range(self.model.nv) if d not in free]
            constraints.append(mink.DofFreezingTask(self.model, dof_indices=frozen))
        return constraints

    def tip(self, arm_q: FloatArray, hand_q: FloatArray, finger: int) -> FloatArray:
        d = self._kinematics
        d.qpos[self.index.arm_qpos] = arm_q
        d.qpos[self.index.hand_qpos] = hand_q
        mujoco.mj_kinematics(self.model, d)
        tip: FloatArray = d.site_xpos[self.index.fingertip_sites[finger]].copy()
        return tip

    def _set(self, arm_q: FloatArray, hand_q: FloatArray) -> None:
        q = self.config.q.copy()
        q[self.index.arm_qpos] = arm_q
        q[self.index.hand_qpos] = hand_q
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
        key = memo_key("finger-track", int(finger), tip, arm_q, hand_q, iterations)
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
        q: FloatArray = self.config.q[self.index.hand_qpos].copy()
        self.memo.put(key, q.copy())
        return q
