"""The MuJoCo driver: the single owner of the physics.

Each control period the runner hands primitives a :class:`Snapshot`; they write set-points
into their own effectors' command slots (:class:`~dial.robot.slots.Slots`). The driver
then applies the slots and steps the physics. Guards (guarded moves) and monitors (watched
spans) are tested after every physics step, so a contact freezes its effector, or fires
its monitor, at the step where it is first sensed. Engine-owned safety monitors run every
period. The driver writes no log: it reports what happened, and the runner records it.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numpy.typing import NDArray

from dial.backend.disturb import Disturbances
from dial.backend.guards import Guard, Guards, Readings
from dial.backend.index import IntArray, RobotIndex
from dial.backend.locate import link_point, tactile_point
from dial.backend.model import (
    finger_bodies,
    hand_actuators,
    hand_angles,
    hand_ctrl,
    joint_loads,
    robot_view,
    tendon_tensions,
)
from dial.backend.safety import Safety
from dial.robot.protocol import (
    Course,
    Fired,
    Happening,
    Monitor,
    Report,
    Robot,
    StopFlag,
    advance_through,
)
from dial.robot.slots import ArmCourse, still
from dial.robot.snapshot import FloatArray, Snapshot, Touch, Trip, frozen
from dial.robot.view import RobotView
from dial.robots.profile import RobotProfile
from dial.scene.thread import Thread, find_threads

CONTROL_PERIOD = 0.01  # s; physics runs at the model's timestep (0.002 s)


def as_slice(index: IntArray) -> slice | IntArray:
    """``index`` as a slice if it is a run of consecutive addresses, else itself."""
    first = int(index[0])
    if np.array_equal(index, np.arange(first, first + len(index))):
        return slice(first, first + len(index))
    return index


class MujocoRobot:
    """The robot protocol (:class:`dial.robot.protocol.Robot`) on a MuJoCo model."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        period: float = CONTROL_PERIOD,
        disturbances: Disturbances | None = None,
        profile: RobotProfile | None = None,
    ) -> None:
        """Drive the robot of ``profile`` (the default robot when None) in ``model``."""
        self.model, self.data = model, data
        self.index = ix = RobotIndex.from_model(model, profile)
        self._fingers = tuple(f.name for f in ix.profile.fingers)
        self._dt = float(model.opt.timestep)  # looked up once: model.opt is slow to reach
        self.substeps = max(1, round(period / self._dt))
        self._period = self.substeps * model.opt.timestep
        self.steps = 0
        self.arm_target = data.qpos[ix.arm_qpos].copy()
        self.hand_target = hand_angles(data, ix)
        self.limp = np.zeros(16, dtype=bool)  # written through set_limp
        self._limping = False  # any limp joint: read every period, kept up to date
        self.threads: tuple[Thread, ...] = find_threads(model)
        self.guards = Guards()
        self.monitors: set[int] = set()  # keys of guards that are monitors (freeze nothing)
        self._trips: dict[int, Trip] = {}
        self._happened: list[Happening] = []
        self._fired: list[Fired] = []
        self.disturbances = disturbances or Disturbances.none()
        self._tactile_adr = [int(a) for a in ix.tactile_sensors]
        rows, cols = ix.profile.hand.taxels
        self._taxels = rows * cols
        self._tactile_shape = (len(self._fingers), rows, cols)
        # The arrays' sensordata, in one fancy index: one copy per snapshot, not one each (a
        # finger without an array reads the first array's, then zeros).
        some = next((a for a in self._tactile_adr if a >= 0), 0)
        self._no_tactile = [f for f, a in enumerate(self._tactile_adr) if a < 0]
        self._tactile_idx = np.concatenate(
            [
                np.arange(a if a >= 0 else some, (a if a >= 0 else some) + rows * cols)
                for a in self._tactile_adr
            ]
        )
        self.safety = Safety(model, data, ix, self._period)
        self._readings = Readings(data, ix, self._tactile_adr)
        # Control addresses as slices where they run in order (they do in dial's models):
        # writing a slice costs a fraction of writing through an index array.
        self._arm_ctrl = as_slice(ix.arm_actuators)
        self._hand_ctrl = as_slice(hand_actuators(ix))
        # Both tendons of a joint servo to its angle (hand_ctrl): where the 32 controls run
        # in order, a (16, 2) view of them takes the 16 angles in one broadcast write.
        controls = data.ctrl[self._hand_ctrl]
        pairs = ix.tendons and ix.full_hand and controls.base is not None
        self._tendon_pairs = controls.reshape(16, 2) if pairs else None
        self._finger_bodies = tuple(
            frozenset(finger_bodies(model, f.joints)) for f in ix.profile.fingers
        )
        self._robot_root = int(model.body_rootid[model.site_bodyid[ix.tool_site]])
        self._taxel_frames: dict[int, tuple[int, FloatArray]] = {}  # see _taxels_of
        self._view = robot_view(model, ix)

    @property
    def view(self) -> RobotView:
        return self._view

    # -- the scheduler's robot protocol ---------------------------------------------------------
    @property
    def period(self) -> float:
        return float(self._period)

    @property
    def time(self) -> float:
        """Simulated s since the first tick."""
        return self.steps * self._dt

    def snapshot(self) -> Snapshot:
        return Snapshot(
            self,
            self.time,
            self.steps,
            frozen(self.arm_target),
            frozen(self.hand_target),
            dict(self._trips) if self._trips else {},
            self.disturbances.dropped,
        )

    @property
    def generation(self) -> int:
        """Physics steps so far: a snapshot's sensors are read at its own step."""
        return self.steps

    def read(self, name: str, hand_target: FloatArray) -> FloatArray:
        """A snapshot's sensor field, read now (dropped-out sensors read as untouched)."""
        d, ix = self.data, self.index
        dropped = self.disturbances.dropped
        # Fancy-indexed arrays are fresh copies: freeze them in place; copy only views.
        if name == "tactile":
            tactile = d.sensordata[self._tactile_idx].reshape(self._tactile_shape)
            for f in self._no_tactile:
                tactile[f] = 0.0
            for kind, f in dropped:
                if kind == "tactile":
                    tactile[f] = 0.0
            return frozen(tactile, fresh=True)
        if name == "differentials":
            differentials = joint_loads(d, ix)
            for kind, f in dropped:
                if kind == "force":
                    differentials[4 * f : 4 * f + 4] = 0.0
            return frozen(differentials, fresh=True)
        if name == "hand_q":
            q = hand_angles(d, ix)
            for kind, f in dropped:
                if kind == "position":
                    q[4 * f : 4 * f + 4] = hand_target[4 * f : 4 * f + 4]
            return frozen(q, fresh=True)
        if name == "arm_q":
            return frozen(d.qpos[ix.arm_qpos], fresh=True)
        if name == "tensions":
            return frozen(tendon_tensions(d, ix), fresh=True)
        if name == "tool_pos":
            return frozen(d.site_xpos[ix.tool_site])
        if name == "tool_rot":
            return frozen(d.site_xmat[ix.tool_site].reshape(3, 3))
        return frozen(d.site_xpos[ix.fingertip_sites], fresh=True)  # tips

    def advance(self) -> Report | None:
        """Apply the slots and step one control period; report what happened, if anything."""
        self._apply()
        m, d = self.model, self.data
        due = self.disturbances.due(self.steps, self.substeps)
        if not self.guards.tested and not self.threads and not due:
            mujoco.mj_step(m, d, nstep=self.substeps)
            self.steps += self.substeps
        else:
            tested, threads = self.guards.tested, self.threads  # read after every physics step
            for _ in range(self.substeps):
                if due:
                    self.disturbances.apply(self.steps, d, self._happened, self.time)
                mujoco.mj_step(m, d)
                self.steps += 1
                for thread in threads:
                    if thread.update(d):
                        fields = {"name": thread.name, "t": self.time, "step": self.steps}
                        self._happened.append(Happening("thread", fields))
                if tested:
                    self._check_guards()
        return self._reported(self.safety.check(self.time, self._happened))

    def _reported(self, fault: str | None) -> Report | None:
        """The period's report, if anything happened (then the robot's lists start afresh)."""
        if fault is None and not self._happened and not self._fired:
            return None
        report = Report(fault, tuple(self._happened), tuple(self._fired))
        self._happened.clear()
        self._fired.clear()
        return report

    def coast(
        self, writes: Sequence[Course], periods: int, stop: StopFlag
    ) -> tuple[int, Report | None]:
        """``advance`` up to ``periods`` times, each after writing that period's set-points
        (``write(k)`` for the k-th); it returns after a period that reports anything, or a
        stop signal, with the number of periods taken. With no guard, thread or disturbance
        in the way this is :meth:`advance` unrolled, as lean as a period can be."""
        n = self.substeps
        if self.guards.tested or self.threads or self.disturbances.due(self.steps, periods * n):
            return advance_through(self, writes, periods, stop)
        m, d, safety, happened = self.model, self.data, self.safety, self._happened
        writes = [w for w in writes if w is not still]
        # Only the arm moves: the hand's controls are written once, not every period.
        arm_only = not self._limping and all(isinstance(w, ArmCourse) for w in writes)
        ctrl, arm_ctrl = d.ctrl, self._arm_ctrl
        self._apply()
        steps, dt = self.steps, self._dt
        for k in range(periods):
            for write in writes:
                write(k)
            if arm_only:
                ctrl[arm_ctrl] = self.arm_target
            else:
                self._apply()
            mujoco.mj_step(m, d, nstep=n)
            self.steps = steps = steps + n
            fault = safety.check(steps * dt, happened)
            if fault is not None or happened:
                return k + 1, self._reported(fault)
            if stop.signal is not None:
                return k + 1, None
        return periods, None

    def hold_all(self) -> None:
        ix = self.index
        self.arm_target = self.data.qpos[ix.arm_qpos].copy()
        self.hand_target = hand_angles(self.data, ix)
        self.set_limp(slice(None), False)
        self.guards.clear()
        self.monitors.clear()
        self._apply()

    def hold(self, effectors: frozenset[str]) -> None:
        """Freeze these effectors at their measured position (a preempted run's)."""
        ix = self.index
        if "arm" in effectors:
            self.arm_target = self.data.qpos[ix.arm_qpos].copy()
        for f, finger in enumerate(self._fingers):
            if finger in effectors:
                joints = slice(4 * f, 4 * f + 4)
                self.hand_target[joints] = hand_angles(self.data, ix)[joints]
                self.set_limp(joints, False)
        self._apply()

    def watch(self, monitor: Monitor) -> int:
        kind, finger, threshold = monitor.contact
        baseline = joint_loads(self.data, self.index)
        guard = Guard(None, ((kind, threshold),), (finger,), baseline, monitor.negated)
        key = self.guards.add(guard)
        self.monitors.add(key)
        return key

    def unwatch(self, key: int) -> None:
        self._untest(key)

    def _untest(self, key: int) -> None:
        self.guards.remove(key)
        self.monitors.discard(key)
        self._trips.pop(key, None)

    # -- what primitives may ask of the robot (through Slots, or read-only) ----------------------
    def set_limp(self, joints: slice | IntArray, on: bool | NDArray[np.bool_]) -> None:
        """Make these hand joints (mask order) back-drivable, or stiff."""
        self.limp[joints] = on
        self._limping = bool(self.limp.any())

    def measured_hand(self) -> FloatArray:
        """(16,) hand joint angles now (rad, mask order)."""
        return hand_angles(self.data, self.index)

    def guard(
        self, effector: str, conditions: Iterable[tuple[str, float]], sense: Iterable[int]
    ) -> int:
        """Guard ``effector``: tested after every physics step until it trips."""
        baseline = joint_loads(self.data, self.index)
        return self.guards.add(Guard(effector, tuple(conditions), tuple(sense), baseline))

    def unguard(self, key: int) -> None:
        self._untest(key)

    def touch(self, finger: int) -> Touch:
        """Where ``finger`` touches now (a dropped-out tactile array locates nothing; see
        :mod:`dial.backend.locate`)."""
        tactile = None
        a = self._tactile_adr[finger]
        if a >= 0 and ("tactile", finger) not in self.disturbances.dropped:
            depths = self.data.sensordata[a : a + self._taxels]
            tactile = tactile_point(depths, self._taxel_points(finger))
        bodies = self._finger_bodies[finger]
        return Touch(tactile, link_point(self.model, self.data, bodies, self._robot_root))

    def _taxel_points(self, finger: int) -> FloatArray:
        """(256, 3) world positions of a fingertip's taxels, in sensor order (m)."""
        geom, local = self._taxels_of(finger)
        rot = self.data.geom_xmat[geom].reshape(3, 3)
        points: FloatArray = self.data.geom_xpos[geom] + local @ rot.T
        return points

    def _taxels_of(self, finger: int) -> tuple[int, FloatArray]:
        """A fingertip's pad geom and its taxels in the geom's frame (looked up once)."""
        known = self._taxel_frames.get(finger)
        if known is not None:
            return known
        model = self.model
        name = self.index.profile.fingers[finger].tactile or ""
        sensor = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name))
        # A tactile sensor's object is its mesh; its reference is the geom that carries it.
        mesh, geom = int(model.sensor_objid[sensor]), int(model.sensor_refid[sensor])
        adr, n = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
        known = self._taxel_frames[finger] = (geom, model.mesh_vert[adr : adr + n].astype(float))
        return known

    # -- stepping ----------------------------------------------------------------------------------
    def _apply(self) -> None:
        d = self.data
        d.ctrl[self._arm_ctrl] = self.arm_target
        target = self.hand_target
        if self._limping:  # limp joints follow their measured angle
            target = np.where(self.limp, hand_angles(d, self.index), target)
        if self._tendon_pairs is not None:
            self._tendon_pairs[:] = target[:, None]
        else:
            d.ctrl[self._hand_ctrl] = hand_ctrl(target, self.index)

    def _check_guards(self) -> None:
        readings = self._readings.at_step(self.hand_target, self.disturbances.dropped)
        for key, guard, trip in self.guards.check(readings, self.steps * self._dt, self.steps):
            if guard.effector is None:  # a monitor: the runner preempts the block
                self._fired.append(Fired(key, trip.time, trip.step))
                self.monitors.discard(key)
                continue
            self._trips[key] = trip = replace(trip, touch=self.touch(trip.finger))
            self._freeze(guard.effector)
            self._happened.append(
                Happening(
                    "contact",
                    {
                        "effector": guard.effector,
                        "sensor": trip.kind,
                        "finger": self._fingers[trip.finger],
                        "value": trip.value,
                        "t": trip.time,
                        "step": trip.step,
                    },
                )
            )

    def _freeze(self, effector: str) -> None:
        """Hold the guarded effector where it is, at this physics step."""
        ix, d = self.index, self.data
        if effector == "arm":
            self.arm_target = d.qpos[ix.arm_qpos].copy()
        else:
            f = self._fingers.index(effector)
            self.hand_target[4 * f : 4 * f + 4] = hand_angles(d, ix)[4 * f : 4 * f + 4]
        self._apply()


if TYPE_CHECKING:  # mypy checks here that the simulated robot implements the whole seam
    _IMPLEMENTS: type[Robot[Snapshot]] = MujocoRobot
