"""The preview's inverse kinematics: the run's (:mod:`dial.backend.ik`), for less.

``dial preview`` solves every target and every waypoint of every straight line the run
would, thousands for a long script; mink's QP machinery costs most of that. :class:`LeanArmIK`
solves the same QP directly, so its answers equal the run's to rounding (docs/debugging.md
gives the figures); :class:`FingerIKOnDemand` is the run's finger IK, set up only when a
script needs it. Like the run's, its answers are memoized (apart from the run's), in the
user's cache folder too, and mink and SciPy load only when it meets a new problem.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from functools import cached_property
from typing import Any, NamedTuple

import mujoco
import numpy as np

from dial.backend.ik import (
    DAMPING,
    DT,
    POS_TOL,
    ROT_TOL,
    ArmIK,
    FingerIK,
)
from dial.robot.memo import memo_key
from dial.robot.snapshot import FloatArray
from dial.robots.profile import RobotProfile

LEAN_ITERATIONS = 30  # per start of LeanArmIK.solve, before it leaves one to mink


class LeanArmIK(ArmIK):
    """:class:`ArmIK` with mink's QP solved directly, for ``dial preview``.

    mink builds and solves a QP for each step of :meth:`ArmIK._iterate`: the frame task's
    damped least squares, the hand frozen, the arm inside its joint limits. Here the same QP,
    from mink's own task error and Jacobian, is solved over the six arm joints: one 6 x 6
    linear solve while no limit binds, else :func:`box_qp`. So a step, a track (a line's
    waypoint) and a solve (a target) equal ArmIK's to rounding (1e-10 rad on the bundled
    scripts), for a fifth of the cost. A start of :meth:`ArmIK.solve` that has not
    converged after :data:`LEAN_ITERATIONS` is left to mink from its beginning, so that a
    target out of reach fails as in the run. Memoized apart from ArmIK (in a file of its
    own, as its code differs), so that a run never reads these answers.
    """

    MEMO = "lean-arm"

    def __init__(
        self, model: mujoco.MjModel | None = None, profile: RobotProfile | None = None
    ) -> None:
        super().__init__(model, profile)
        self.MEMO = f"lean-arm:{self.robot}"
        self._qpos, self._dof = _as_slice(self.index.arm_qpos), _as_slice(self.index.arm_dof)
        self._velocity = np.zeros(self.model.nv)
        self._tools: dict[bytes, FloatArray] = {}  # fk (position, rotation) where tracks ended

    @cached_property
    def _qp(self) -> _QP:
        """mink's weights, gain, damping and joint-limit bounds of a step, from its own frame
        task and limit: made when the first solve needs them (mink loads then)."""
        from scipy.linalg import lapack

        limit, task, qpos = self.limits[0], self.task, self.index.arm_qpos
        assert task.lm_damping == 0.0, "the frame task's own damping is not modelled here"
        return _QP(
            lapack.dgesv,
            (task.cost * -task.gain, task.cost[:, None]),
            DAMPING * np.eye(len(qpos)),  # mink's, as its task adds none of its own
            (limit.gain * limit.lower[qpos], limit.gain * limit.upper[qpos], limit.gain),
        )

    def fk(self, arm_q: FloatArray) -> tuple[FloatArray, FloatArray]:
        known = self._tools.get(np.asarray(arm_q, dtype=np.float64).tobytes())
        if known is None:
            return super().fk(arm_q)
        return known[:3].copy(), known[3:].reshape(3, 3).copy()

    def track(
        self,
        pos: FloatArray,
        rot: FloatArray,
        arm_q: FloatArray,
        iterations: int = 2,
        guide: FloatArray | None = None,
    ) -> FloatArray:
        """:meth:`ArmIK.track`, the lean way (a redundant arm's guided line: mink's QP)."""
        if guide is not None and self.redundant:
            return super().track(pos, rot, arm_q, iterations, guide)
        key = memo_key(f"{self.MEMO}-track", pos, rot, arm_q, iterations)
        known = self.memo.get(key)
        if isinstance(known, np.ndarray):
            return known.copy()
        self._set(arm_q)
        self._iterate(pos, rot, iterations)
        q: FloatArray = self.config.data.qpos[self._qpos].copy()
        self.memo.put(key, q.copy())
        return q

    def _set(self, arm_q: FloatArray) -> None:
        data = self.config.data
        if data.qpos[self._qpos].tobytes() != np.asarray(arm_q, dtype=np.float64).tobytes():
            data.qpos[self._qpos] = arm_q
            self.config.update()

    def _iterate(
        self, pos: FloatArray, rot: FloatArray, iterations: int, posture: bool = False
    ) -> tuple[float, float]:
        if self.redundant:  # a posture task: mink's QP as it is
            return super()._iterate(pos, rot, iterations, posture)
        import mink

        task, config = self.task, self.config
        target = np.empty(7)
        mujoco.mju_mat2Quat(target[:4], np.ascontiguousarray(rot, dtype=np.float64).ravel())
        target[4:] = pos
        task.transform_target_to_world = mink.SE3(wxyz_xyz=target)  # set_target, less a copy
        start = config.data.qpos.copy() if iterations > LEAN_ITERATIONS else None
        perr = rerr = np.inf
        for _ in range(min(iterations, LEAN_ITERATIONS)):
            err = task.compute_error(config)
            perr, rerr = math.sqrt(err[:3].dot(err[:3])), math.sqrt(err[3:].dot(err[3:]))
            if perr < POS_TOL and rerr < ROT_TOL:
                break
            step = self._step(err, task.compute_jacobian(config)[:, self._dof])
            self._velocity[self._dof] = step / DT
            config.integrate_inplace(self._velocity, DT)
        else:
            if iterations > LEAN_ITERATIONS:  # a solve that does not converge soon: mink's
                config.update(start)
                return super()._iterate(pos, rot, iterations)
        self._remember_tool()
        return perr, rerr

    def _remember_tool(self) -> None:
        """The tool pose where a track ended, for :meth:`fk` (a line's check asks for it)."""
        if len(self._tools) > 10_000:
            self._tools.clear()
        data, site = self.config.data, self.index.tool_site
        pose = np.concatenate((data.site_xpos[site], data.site_xmat[site]))
        self._tools[data.qpos[self._qpos].tobytes()] = pose

    def _step(self, err: FloatArray, jac: FloatArray) -> FloatArray:
        """The step mink's QP takes (its weights, gain, damping and joint-limit bounds)."""
        dgesv, (error_weights, jac_weights), damping, (low, high, gain) = self._qp
        error, weighted = error_weights * err, jac_weights * jac
        hessian = weighted.T @ weighted
        hessian += damping
        gradient = error @ weighted
        step: FloatArray = dgesv(hessian, gradient)[2]  # as numpy.linalg.solve
        moved = gain * self.config.data.qpos[self._qpos]
        low, high = low - moved, high - moved
        if np.count_nonzero(step < low) or np.count_nonzero(step > high):
            return box_qp(hessian, gradient, low, high)
        return step


class _QP(NamedTuple):
    dgesv: Callable[..., tuple[Any, ...]]  # LAPACK's solver (SciPy's), as numpy.linalg.solve
    weights: tuple[FloatArray, FloatArray]  # of the task error, and of the Jacobian's rows
    damping: FloatArray
    reach: tuple[FloatArray, FloatArray, float]  # the limits' lower and upper bounds, gain


def box_qp(hessian: FloatArray, b: FloatArray, low: FloatArray, high: FloatArray) -> FloatArray:
    """argmin 1/2 x'Hx - b'x with ``low <= x <= high`` (H positive definite; low <= high).

    A primal active-set method: from a feasible point, solve for the free variables with the
    bound ones held; step toward that solution until a bound blocks (it joins the bound set);
    at a solution, free the bound variable whose multiplier has the wrong sign, if any.
    Exact to rounding: daqp, mink's QP solver, agrees to 1e-14.
    """
    n = len(b)
    x = np.minimum(np.maximum(np.zeros(n), low), high)
    side = np.zeros(n, dtype=np.int8)  # -1 held at its low bound, +1 at its high one, 0 free
    for _ in range(10 * n):
        free, held = np.flatnonzero(side == 0), np.flatnonzero(side != 0)
        goal = x.copy()
        if len(free):
            rhs = b[free] - hessian[np.ix_(free, held)] @ x[held]
            goal[free] = np.linalg.solve(hessian[np.ix_(free, free)], rhs)
        way = goal - x
        with np.errstate(divide="ignore", invalid="ignore"):
            room = np.where(way < 0, (low - x) / way, np.where(way > 0, (high - x) / way, np.inf))
        room[held] = np.inf
        block = int(np.argmin(room))
        if room[block] < 1.0:  # a bound blocks the way: go to it, hold the variable there
            x += room[block] * way
            x[block] = low[block] if way[block] < 0 else high[block]
            side[block] = -1 if way[block] < 0 else 1
            continue
        x = goal
        force = hessian @ x - b  # the multipliers of the held bounds
        wrong = np.flatnonzero(((side < 0) & (force < 0)) | ((side > 0) & (force > 0)))
        if not len(wrong):
            return x
        side[wrong[np.argmax(np.abs(force[wrong]))]] = 0
    raise ArithmeticError("the step's QP did not settle")  # finite for a convex QP


def _as_slice(index: np.ndarray) -> slice | np.ndarray:
    """A run of consecutive indices as a slice (cheaper to index with), else as it is."""
    first = int(index[0])
    if np.array_equal(index, np.arange(first, first + len(index))):
        return slice(first, first + len(index))
    return index


class FingerIKOnDemand(FingerIK):
    """The fingers' IK, on a copy of the arm's model, set up when a run first uses it (most
    scripts never do)."""

    def __init__(  # FingerIK's own waits for _ready
        self, model: mujoco.MjModel, profile: RobotProfile | None = None
    ) -> None:
        self._pending: mujoco.MjModel | None = model
        self._profile = profile

    def _ready(self) -> None:
        if self._pending is not None:
            model, self._pending = self._pending, None
            super().__init__(copy.copy(model), self._profile)

    # The two ways in (their arguments as FingerIK's, which callers are checked against).
    def tip(self, *args: Any, **kwargs: Any) -> FloatArray:
        self._ready()
        return super().tip(*args, **kwargs)

    def track(self, *args: Any, **kwargs: Any) -> FloatArray:
        self._ready()
        return super().track(*args, **kwargs)
