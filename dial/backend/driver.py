"""The MuJoCo driver: the single owner of the physics.

Each control period the runner hands primitives a :class:`Snapshot`; they write
set-points into their own effectors' command slots (:class:`Slots`). The driver
then applies the slots and steps the physics. Guards armed by guarded moves are
checked after every physics step, so a contact freezes its effector at the step
where it is first sensed. Engine-owned safety monitors run every period.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, replace

import mujoco
import numpy as np
import trio

from dial.backend.contact import contact_reading
from dial.backend.locate import finger_bodies, link_point, tactile_point
from dial.backend.model import HAND_JOINTS, RobotIndex, hand_ctrl, tendon_differentials
from dial.backend.snapshot import FloatArray, Snapshot, Trip, frozen
from dial.errors import DialError
from dial.instructions.types import FINGERS
from dial.scene.thread import Thread, find_threads
from dial.scheduler.log import EventLog

CONTROL_PERIOD = 0.01  # s; physics runs at the model's timestep (0.002 s)
SATURATION_LIMIT_S = 1.0  # a tendon pinned at its tension limit this long is logged
LIMIT_SLACK = 0.05  # rad: the servo may press a joint this far into its limit stop


class EffectorError(DialError):
    """A primitive wrote to an effector its run does not own (a bug, not a script error)."""


@dataclass
class Guard:
    """Stop ``effector`` when any condition holds on any of the ``sense`` fingers."""

    effector: str  # "arm" or a finger name
    conditions: tuple[tuple[str, float], ...]
    sense: tuple[int, ...]
    baseline: FloatArray  # (16,) differentials when armed, for force conditions


class MujocoRobot:
    """The robot protocol of :mod:`dial.scheduler` on a MuJoCo model."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        log: EventLog | None = None,
        period: float = CONTROL_PERIOD,
    ) -> None:
        self.model, self.data = model, data
        self.index = RobotIndex.from_model(model)
        self.log = log or EventLog()
        self.substeps = max(1, round(period / model.opt.timestep))
        self._period = self.substeps * model.opt.timestep
        self.steps = 0
        ix = self.index
        self.arm_target = data.qpos[ix.arm_qpos].copy()
        self.hand_target = data.qpos[ix.hand_qpos].copy()
        self.limp = np.zeros(16, dtype=bool)
        self.threads: tuple[Thread, ...] = find_threads(model)
        self.guards: dict[int, Guard] = {}
        self._next_guard = 0
        self._trips: dict[int, Trip] = {}
        self._saturated_since = np.full(32, -1.0)
        self._saturation_logged = np.zeros(32, dtype=bool)
        self._tactile_adr = [int(a) for a in ix.tactile_sensors]
        # The four arrays' sensordata, in one fancy index: one copy per snapshot, not four.
        self._tactile_idx = np.concatenate([np.arange(a, a + 256) for a in self._tactile_adr])
        # Views of MuJoCo's warning counters, looked up once: they follow data.warning.
        self._divergence = [data.warning[w] for w in _DIVERGENCE]
        arm_range = model.jnt_range[model.actuator_trnid[ix.arm_actuators, 0]]
        self._arm_lo = arm_range[:, 0] - LIMIT_SLACK
        self._arm_hi = arm_range[:, 1] + LIMIT_SLACK
        self._pinned_at = ix.tension_limit - 1e-6
        self._finger_bodies = tuple(finger_bodies(model, f) for f in range(len(FINGERS)))
        hand_joints = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in HAND_JOINTS]
        self.hand_range = model.jnt_range[hand_joints].copy()  # (16, 2) rad, mask order
        self.pace: float | None = None  # wall seconds per simulated second, for --realtime

    # -- the scheduler's robot protocol ---------------------------------------------------------
    @property
    def period(self) -> float:
        return float(self._period)

    def snapshot(self) -> Snapshot:
        d, ix = self.data, self.index
        # Fancy-indexed arrays are fresh copies: freeze them in place; copy only views.
        return Snapshot(
            time=self.time,
            step=self.steps,
            arm_q=frozen(d.qpos[ix.arm_qpos], fresh=True),
            arm_target=frozen(self.arm_target),
            hand_q=frozen(d.qpos[ix.hand_qpos], fresh=True),
            hand_target=frozen(self.hand_target),
            tensions=frozen(d.sensordata[ix.tension_sensors], fresh=True),
            differentials=frozen(tendon_differentials(d, ix), fresh=True),
            tactile=frozen(self.tactile(), fresh=True),
            tool_pos=frozen(d.site_xpos[ix.tool_site]),
            tool_rot=frozen(d.site_xmat[ix.tool_site].reshape(3, 3)),
            tips=frozen(d.site_xpos[ix.fingertip_sites], fresh=True),
            trips=dict(self._trips),
        )

    async def advance(self) -> str | None:
        self._apply()
        m, d = self.model, self.data
        if not self.guards and not self.threads:
            mujoco.mj_step(m, d, nstep=self.substeps)
            self.steps += self.substeps
        else:
            for _ in range(self.substeps):
                mujoco.mj_step(m, d)
                self.steps += 1
                for thread in self.threads:
                    if thread.update(d):
                        self.log.write("thread", name=thread.name, t=self.time, step=self.steps)
                if self.guards:
                    self._check_guards()
        fault = self._monitor()
        if self.pace is not None:
            await trio.sleep(self._period * self.pace)
        else:
            await trio.lowlevel.checkpoint()
        return fault

    def hold_all(self) -> None:
        ix = self.index
        self.arm_target = self.data.qpos[ix.arm_qpos].copy()
        self.hand_target = self.data.qpos[ix.hand_qpos].copy()
        self.limp[:] = False
        self.guards.clear()
        self._apply()

    # -- commands ----------------------------------------------------------------------------------
    @property
    def time(self) -> float:
        return self.steps * float(self.model.opt.timestep)

    def tactile(self) -> FloatArray:
        """(4, 16, 16) taxel depths (m)."""
        depths: FloatArray = self.data.sensordata[self._tactile_idx].reshape(4, 16, 16)
        return depths

    def _apply(self) -> None:
        ix, d = self.index, self.data
        d.ctrl[ix.arm_actuators] = self.arm_target
        target = np.where(self.limp, d.qpos[ix.hand_qpos], self.hand_target)
        d.ctrl[ix.tendon_actuators] = hand_ctrl(target)

    # -- guards -----------------------------------------------------------------------------------
    def arm_guard(
        self, effector: str, conditions: Iterable[tuple[str, float]], sense: Iterable[int]
    ) -> int:
        """Arm a guard; it is checked after every physics step until disarmed."""
        baseline = tendon_differentials(self.data, self.index)
        guard = Guard(effector, tuple(conditions), tuple(sense), baseline)
        self._next_guard += 1
        self.guards[self._next_guard] = guard
        return self._next_guard

    def disarm(self, guard_id: int) -> None:
        self.guards.pop(guard_id, None)
        self._trips.pop(guard_id, None)

    def _check_guards(self) -> None:
        d, ix = self.data, self.index
        differentials = tendon_differentials(d, ix)
        q = d.qpos[ix.hand_qpos]
        for gid, guard in list(self.guards.items()):
            trip = self._first_trip(guard, differentials, q)
            if trip is not None:
                self._trip(gid, guard, trip)

    def _first_trip(self, guard: Guard, differentials: FloatArray, q: FloatArray) -> Trip | None:
        sd = self.data.sensordata
        for kind, threshold in guard.conditions:
            for f in guard.sense:
                a = self._tactile_adr[f]
                value = contact_reading(
                    kind, f, sd[a : a + 256], differentials, self.hand_target, q, guard.baseline
                )
                if value >= threshold:
                    return self._located(Trip(self.time, self.steps, kind, f, value))
        return None

    def _located(self, trip: Trip) -> Trip:
        """``trip`` with where its finger touches at this physics step."""
        m, d, f = self.model, self.data, trip.finger
        a = self._tactile_adr[f]
        tactile = tactile_point(m, d, f, d.sensordata[a : a + 256])
        link = link_point(m, d, self._finger_bodies[f])
        return replace(trip, tactile=tactile, link=link)

    def _trip(self, gid: int, guard: Guard, trip: Trip) -> None:
        self._trips[gid] = trip
        del self.guards[gid]
        ix, d = self.index, self.data
        # Freeze the guarded effector where it is, at this physics step.
        if guard.effector == "arm":
            self.arm_target = d.qpos[ix.arm_qpos].copy()
        else:
            f = FINGERS.index(guard.effector)
            self.hand_target[4 * f : 4 * f + 4] = d.qpos[ix.hand_qpos[4 * f : 4 * f + 4]]
        self._apply()
        self.log.write(
            "contact",
            effector=guard.effector,
            sensor=trip.kind,
            finger=FINGERS[trip.finger],
            value=trip.value,
            t=trip.time,
            step=trip.step,
        )

    # -- safety monitors --------------------------------------------------------------------------
    def _monitor(self) -> str | None:
        d, ix = self.data, self.index
        # MuJoCo resets the state itself when it meets a bad qacc/qpos/qvel, and counts a
        # warning: a nonzero count is the divergence (the state is no longer the run's).
        for warning in self._divergence:
            if warning.number:
                return "the physics diverged (MuJoCo reset an unstable state)"
        q = d.qpos[ix.arm_qpos]
        if ((q < self._arm_lo) | (q > self._arm_hi)).any():
            j = int(np.flatnonzero((q < self._arm_lo) | (q > self._arm_hi))[0])
            return f"PUMA joint {j + 1} is beyond its limit ({np.degrees(q[j]):.1f} deg)"
        # A tendon pinned at its limit is not a fault (a fist pressed into the palm does it),
        # but a researcher should know: log it once per episode.
        pinned = d.sensordata[ix.tension_sensors] >= self._pinned_at
        if not pinned.any() and not self._saturation_logged.any():
            self._saturated_since.fill(-1.0)
            return None
        self._saturated_since[~pinned] = -1.0
        self._saturated_since[pinned & (self._saturated_since < 0)] = self.time
        held = pinned & (self.time - self._saturated_since >= SATURATION_LIMIT_S)
        for k in np.flatnonzero(held & ~self._saturation_logged):
            joint = int(k) // 2
            self.log.write(
                "warning",
                t=self.time,
                message=f"{FINGERS[joint // 4]} joint {joint % 4} "
                f"{'flexor' if k % 2 == 0 else 'extensor'} tendon held at its "
                f"{ix.tension_limit:g} N limit for {SATURATION_LIMIT_S:g} s",
            )
        self._saturation_logged = held | (self._saturation_logged & pinned)
        return None


_DIVERGENCE = (
    mujoco.mjtWarning.mjWARN_BADQACC,
    mujoco.mjtWarning.mjWARN_BADQPOS,
    mujoco.mjtWarning.mjWARN_BADQVEL,
)


class Slots:
    """The command slots a run owns: it may write only its own effectors."""

    def __init__(self, robot: MujocoRobot, effectors: frozenset[str]) -> None:
        self.robot, self.effectors = robot, effectors

    def _own(self, effector: str) -> None:
        if effector not in self.effectors:
            raise EffectorError(f"run does not own the {effector}")

    def arm(self, q: FloatArray) -> None:
        self._own("arm")
        self.robot.arm_target = np.array(q, dtype=np.float64)

    def joints(self, mask: int, q16: FloatArray) -> None:
        """Set the hand joints selected by ``mask`` (bit 4*f + j) from ``q16``."""
        bits = [k for k in range(16) if mask >> k & 1]
        for f in {k // 4 for k in bits}:
            self._own(FINGERS[f])
        self.robot.hand_target[bits] = np.asarray(q16)[bits]

    def limp(self, mask: int, on: bool) -> None:
        bits = [k for k in range(16) if mask >> k & 1]
        for f in {k // 4 for k in bits}:
            self._own(FINGERS[f])
        self.robot.limp[bits] = on
        if not on:  # the joints hold where they went
            self.robot.hand_target[bits] = self.robot.data.qpos[self.robot.index.hand_qpos[bits]]
