"""Inverse kinematics with mink on a robot-only copy of the model.

The IK model holds only the arm and hand (no scene objects), so its QP stays at
22 velocities whatever the scene holds. Solutions are warm-started from the last
one: a straight-line move solves one waypoint per control period.
"""

from __future__ import annotations

import math
from collections import OrderedDict

import mink
import mujoco
import numpy as np
from scipy.linalg import lapack

from dial.backend.model import RobotIndex, load_model
from dial.backend.snapshot import FloatArray
from dial.errors import DialError

SOLVER = "daqp"
DT = 0.01  # s: the differential step of one solve
POS_TOL = 5e-4  # m
ROT_TOL = 2e-3  # rad
SOLVE_ITERATIONS = 200  # per start of ArmIK.solve
LEAN_ITERATIONS = 30  # per start of LeanArmIK.solve, before it leaves one to mink
DAMPING = 1e-3  # mink's Levenberg-Marquardt damping of every step


class IKError(DialError):
    """A target the arm or a finger cannot reach; the message says how far off it stays."""


class _Memo:
    """Solutions already found in this process, by their exact inputs.

    A solve depends only on its inputs (the solvers keep no state between calls that
    changes a result), so a repeated problem gives back the very same array: the runs of a
    script in one process (a sweep's trials, a notebook, a benchmark) solve the same
    targets, since locations follow the *believed* object poses. Bounded, oldest first out.
    """

    SIZE = 50_000

    def __init__(self) -> None:
        self._values: OrderedDict[tuple[object, ...], object] = OrderedDict()

    @staticmethod
    def key(kind: str, *parts: object) -> tuple[object, ...]:
        return (
            kind,
            *(
                np.ascontiguousarray(p, dtype=np.float64).tobytes()
                if isinstance(p, np.ndarray)
                else p
                for p in parts
            ),
        )

    def get(self, key: tuple[object, ...]) -> object:
        return self._values.get(key)

    def clear(self) -> None:
        self._values.clear()

    def put(self, key: tuple[object, ...], value: object) -> None:
        self._values[key] = value
        if len(self._values) > self.SIZE:
            self._values.popitem(last=False)


_MEMO = _Memo()


def forget_solutions() -> None:
    """Empty the memo: the next solves cost what they cost in a fresh process (benchmarks)."""
    _MEMO.clear()


class _Base:
    def __init__(self, model: mujoco.MjModel | None = None) -> None:
        """On the robot-only model, compiled, or ``model`` (one; for several solvers)."""
        self.model = load_model() if model is None else model
        self.index = RobotIndex.from_model(self.model)
        self.config = mink.Configuration(self.model)
        self.limits = [mink.ConfigurationLimit(self.model)]

    def _site(self, name: str) -> int:
        return int(mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, name))


class ArmIK(_Base):
    """Tool-frame (``hand_palm``) IK over the six PUMA joints."""

    MEMO = "arm"  # the memo's name for this solver's results

    def __init__(self, model: mujoco.MjModel | None = None) -> None:
        super().__init__(model)
        self.task = mink.FrameTask("hand_palm", "site", position_cost=1.0, orientation_cost=0.2)
        hand = [int(d) for d in self.index.hand_dof]
        self.constraints = [mink.DofFreezingTask(self.model, dof_indices=hand)]

    def fk(self, arm_q: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Tool position (3,) and rotation (3, 3) at ``arm_q``."""
        self._set(arm_q)
        site = self.index.tool_site
        d = self.config.data
        return d.site_xpos[site].copy(), d.site_xmat[site].reshape(3, 3).copy()

    def _set(self, arm_q: FloatArray) -> None:
        q = self.config.q.copy()
        q[self.index.arm_qpos] = arm_q
        self.config.update(q)

    def _iterate(self, pos: FloatArray, rot: FloatArray, iterations: int) -> tuple[float, float]:
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
        key = _Memo.key(f"{self.MEMO}-track", pos, rot, arm_q, iterations)
        known = _MEMO.get(key)
        if isinstance(known, np.ndarray):
            return known.copy()
        self._set(arm_q)
        self._iterate(pos, rot, iterations)
        q: FloatArray = self.config.q[self.index.arm_qpos].copy()
        _MEMO.put(key, q.copy())
        return q

    def solve(self, pos: FloatArray, rot: FloatArray, arm_q: FloatArray, what: str) -> FloatArray:
        """Converge on the pose; raise :class:`IKError` if it is out of reach.

        Differential IK from ``arm_q`` finds the solution in its own basin, which is the one
        to keep (no wrist flip). It can stall against a joint limit far from the goal; then
        fixed wrist and elbow variations of the start are tried in order, and the first that
        converges wins. Deterministic.
        """
        start = np.asarray(arm_q, dtype=np.float64)
        key = _Memo.key(f"{self.MEMO}-solve", pos, rot, start)
        known = _MEMO.get(key)
        closest = known if isinstance(known, tuple) else (np.inf, np.inf)
        if isinstance(known, np.ndarray):
            return known.copy()
        for offset in _SEEDS if known is None else ():
            self._set(start + offset)
            perr, rerr = self._iterate(pos, rot, SOLVE_ITERATIONS)
            if perr <= 2e-3 and rerr <= 1e-2:
                q: FloatArray = self.config.q[self.index.arm_qpos].copy()
                _MEMO.put(key, q.copy())
                return q
            closest = min(closest, (perr, rerr))
        _MEMO.put(key, closest)
        raise IKError(
            f"{what} is out of the arm's reach: the tool stays {closest[0] * 1000:.1f} mm "
            f"and {np.degrees(closest[1]):.1f} deg away"
        )


class LeanArmIK(ArmIK):
    """:class:`ArmIK` with mink's QP solved directly, for ``dial preview``.

    mink builds and solves a QP for each step of :meth:`ArmIK._iterate`: the frame task's
    damped least squares, the hand frozen, the arm inside its joint limits. Here the same QP,
    from mink's own task error and Jacobian, is solved over the six arm joints: one 6 x 6
    linear solve while no limit binds, else :func:`box_qp`. So a step, a track (a line's
    waypoint) and a solve (a target) equal ArmIK's to rounding (1e-10 rad on the bundled
    scripts), for a fifth of the cost. A start of :meth:`ArmIK.solve` that has not
    converged after :data:`LEAN_ITERATIONS` is left to mink from its beginning, so that a
    target out of reach fails as in the run. Memoized apart from ArmIK, so that a run never
    reads these answers.
    """

    MEMO = "lean-arm"

    def __init__(self, model: mujoco.MjModel | None = None) -> None:
        super().__init__(model)
        limit, task, qpos = self.limits[0], self.task, self.index.arm_qpos
        self._qpos, self._dof = _as_slice(qpos), _as_slice(self.index.arm_dof)
        self._reach = (limit.gain * limit.lower[qpos], limit.gain * limit.upper[qpos], limit.gain)
        self._weights = (task.cost * -task.gain, task.cost[:, None])
        self._velocity = np.zeros(self.model.nv)
        self._damping = DAMPING * np.eye(len(qpos))  # mink's, as its task adds none of its own
        assert task.lm_damping == 0.0, "the frame task's own damping is not modelled here"
        self._tools: dict[bytes, tuple[FloatArray, FloatArray]] = {}  # fk where tracks ended

    def fk(self, arm_q: FloatArray) -> tuple[FloatArray, FloatArray]:
        known = self._tools.get(np.asarray(arm_q, dtype=np.float64).tobytes())
        if known is None:
            return super().fk(arm_q)
        return known[0].copy(), known[1].copy()

    def _set(self, arm_q: FloatArray) -> None:
        data = self.config.data
        if data.qpos[self._qpos].tobytes() != np.asarray(arm_q, dtype=np.float64).tobytes():
            data.qpos[self._qpos] = arm_q
            self.config.update()

    def _iterate(self, pos: FloatArray, rot: FloatArray, iterations: int) -> tuple[float, float]:
        task, config = self.task, self.config
        target = np.empty(7)
        mujoco.mju_mat2Quat(target[:4], np.ascontiguousarray(rot, dtype=np.float64).ravel())
        target[4:] = pos
        task.transform_target_to_world = mink.SE3(wxyz_xyz=target)  # set_target, less a copy
        start = config.data.qpos.copy()
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
        pose = (data.site_xpos[site].copy(), data.site_xmat[site].reshape(3, 3).copy())
        self._tools[data.qpos[self._qpos].tobytes()] = pose

    def _step(self, err: FloatArray, jac: FloatArray) -> FloatArray:
        """The step mink's QP takes (its weights, gain, damping and joint-limit bounds)."""
        error_weights, jac_weights = self._weights
        error, weighted = error_weights * err, jac_weights * jac
        hessian = weighted.T @ weighted
        hessian += self._damping
        gradient = error @ weighted
        step: FloatArray = lapack.dgesv(hessian, gradient)[2]  # as numpy.linalg.solve
        low, high, gain = self._reach
        moved = gain * self.config.data.qpos[self._qpos]
        low, high = low - moved, high - moved
        if np.count_nonzero(step < low) or np.count_nonzero(step > high):
            return box_qp(hessian, gradient, low, high)
        return step


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

    def __init__(self, model: mujoco.MjModel | None = None) -> None:
        super().__init__(model)
        ix = self.index
        self.tasks = [
            mink.FrameTask(f"hand_{f}_tip", "site", position_cost=1.0, orientation_cost=0.0)
            for f in ("index", "middle", "ring", "thumb")
        ]
        self.constraints = []
        for f in range(4):
            free = {int(d) for d in ix.hand_dof[4 * f : 4 * f + 4]}
            frozen = [d for d in range(self.model.nv) if d not in free]
            self.constraints.append(mink.DofFreezingTask(self.model, dof_indices=frozen))

    def tip(self, arm_q: FloatArray, hand_q: FloatArray, finger: int) -> FloatArray:
        self._set(arm_q, hand_q)
        tip: FloatArray = self.config.data.site_xpos[self.index.fingertip_sites[finger]].copy()
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
        key = _Memo.key("finger-track", finger, tip, arm_q, hand_q, iterations)
        known = _MEMO.get(key)
        if isinstance(known, np.ndarray):
            return known.copy()
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
        _MEMO.put(key, q.copy())
        return q
