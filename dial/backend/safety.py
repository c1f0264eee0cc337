"""Engine-owned safety monitors, checked every control period; the script cannot switch
them off: a diverged (non-finite) physics state, arm joints beyond their limits, and hand
drives held at their limit (a tendon at its tension limit, a joint servo at its torque
limit: a warning, not a fault). The slack and the time are the robot profile's limits."""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np

from dial.backend.index import RobotIndex
from dial.robot.protocol import Happening

_DIVERGENCE = (
    mujoco.mjtWarning.mjWARN_BADQACC,
    mujoco.mjtWarning.mjWARN_BADQPOS,
    mujoco.mjtWarning.mjWARN_BADQVEL,
)


class Safety:
    """The safety monitors of one robot."""

    def __init__(
        self, model: mujoco.MjModel, data: mujoco.MjData, index: RobotIndex, period: float
    ) -> None:
        self.data, self.index = data, index
        # Views of MuJoCo's warning counters, looked up once: they follow data.warning.
        self._divergence = [data.warning[w] for w in _DIVERGENCE]
        # A reset sets the time to 0, so a period ends before this (reading the counters
        # costs more than reading the time): at most period - 1 step after the reset.
        self._span = period - 0.5 * float(model.opt.timestep)
        self._due = data.time + self._span
        limits = index.profile.limits
        self._hold_s = limits.saturation_time  # a drive pinned at its limit this long is logged
        arm_range = model.jnt_range[model.actuator_trnid[index.arm_actuators, 0]]
        # Six comparisons a period: on Python floats, by index, they cost a tenth of numpy's
        # and half of a zip's over (lo, hi) pairs.
        slack = limits.joint_slack  # rad: the servo may press a joint this far into its stop
        self._lo = (arm_range[:, 0] - slack).tolist()
        self._hi = (arm_range[:, 1] + slack).tolist()
        self._arm_joints = range(len(self._lo))
        self._pinned_at = index.load_limit - 1e-6
        # Views where the addresses run in order (a read through them copies nothing).
        self._arm_q = _view(data.qpos, index.arm_qpos)
        self._loads = _loads(data, index)
        n = len(index.tendon_actuators) or len(index.hand_actuators)
        self.saturated_since = np.full(n, -1.0)
        self.saturation_logged = np.zeros(n, dtype=bool)
        self._tracking = False  # a drive is pinned now, or one was logged and still is

    def check(self, time: float, happened: list[Happening]) -> str | None:
        """A fault message, or None; appends a ``warning`` for a drive held at its limit."""
        # MuJoCo resets the state itself when it meets a bad qacc/qpos/qvel, and counts a
        # warning: a nonzero count is the divergence (the state is no longer the run's).
        now = self.data.time
        if now < self._due:
            for warning in self._divergence:
                if warning.number:
                    return "the physics diverged (MuJoCo reset an unstable state)"
        self._due = now + self._span
        q, lo, hi = self._arm_q().tolist(), self._lo, self._hi
        for j in self._arm_joints:
            if not lo[j] <= q[j] <= hi[j]:
                return self._beyond(j)
        # A drive pinned at its limit is not a fault (a fist pressed into the palm does it),
        # but a researcher should know: log it once per episode.
        loads = self._loads()
        # The common case. The largest load through argmax: numpy's max (its reduction
        # machinery) costs four times as much, and more just after a physics step.
        if not self._tracking and loads.item(loads.argmax()) < self._pinned_at:
            return None
        pinned = loads >= self._pinned_at
        if not pinned.any() and not self.saturation_logged.any():
            self.saturated_since.fill(-1.0)
            self._tracking = False
            return None
        self._tracking = True
        self.saturated_since[~pinned] = -1.0
        self.saturated_since[pinned & (self.saturated_since < 0)] = time
        held = pinned & (time - self.saturated_since >= self._hold_s)
        for k in np.flatnonzero(held & ~self.saturation_logged):
            message = f"{self._drive(int(k))} held at its {self._limit} for {self._hold_s:g} s"
            happened.append(Happening("warning", {"t": time, "message": message}))
        self.saturation_logged = held | (self.saturation_logged & pinned)
        return None

    def restore(self, saturated_since: np.ndarray, saturation_logged: np.ndarray) -> None:
        """Take up the tendon timers of a saved run (state files): tracked again at once if a
        tendon was pinned or logged, as the run that saved them would be."""
        self.saturated_since[:] = saturated_since
        self.saturation_logged[:] = saturation_logged
        self._tracking = bool(self.saturation_logged.any() or (self.saturated_since >= 0).any())
        self._due = self.data.time + self._span

    @property
    def _limit(self) -> str:
        unit = "N" if self.index.tendons else "N m"
        return f"{self.index.load_limit:g} {unit} limit"

    def _drive(self, k: int) -> str:
        """A drive by its joint: "index joint 0 flexor tendon", "thumb joint 2"."""
        ix = self.index
        joint = k // 2 if ix.tendons else k
        bit = int(ix.hand_bits[joint])
        name = f"{ix.profile.fingers[bit // 4].name} joint {bit % 4}"
        if not ix.tendons:
            return name
        return f"{name} {'flexor' if k % 2 == 0 else 'extensor'} tendon"

    def _beyond(self, j: int) -> str:
        """The fault message of arm joint ``j`` (from 0), beyond its limit."""
        arm = self.index.profile.arm.name
        angle = self._arm_q().item(j)
        return f"{arm} joint {j + 1} is beyond its limit ({np.degrees(angle):.1f} deg)"


def _loads(data: mujoco.MjData, index: RobotIndex) -> Callable[[], np.ndarray]:
    """A reader of the hand drives' loads: tendon tensions (never negative), or the size of
    the joint servos' torques."""
    if index.tendons:
        return _view(data.sensordata, index.load_sensors)
    raw = (
        _view(data.actuator_force, index.hand_actuators)
        if index.profile.hand.load == "actuator"
        else _view(data.sensordata, index.load_sensors)
    )
    return lambda: np.abs(raw())


def _view(array: np.ndarray, index: np.ndarray) -> Callable[[], np.ndarray]:
    """A reader of ``array[index]``: a view when ``index`` runs in order, else a copy."""
    first = int(index[0])
    if np.array_equal(index, np.arange(first, first + len(index))):
        view = array[first : first + len(index)]
        return lambda: view
    return lambda: array[index]
