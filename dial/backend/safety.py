"""Engine-owned safety monitors, checked every control period; the script cannot switch
them off: a diverged (non-finite) physics state, arm joints beyond their limits, and
tendons held at their tension limit (a warning, not a fault)."""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np

from dial.backend.model import RobotIndex
from dial.instructions.types import FINGERS
from dial.robot.protocol import Happening

SATURATION_LIMIT_S = 1.0  # a tendon pinned at its tension limit this long is logged
LIMIT_SLACK = 0.05  # rad: the servo may press a joint this far into its limit stop

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
        arm_range = model.jnt_range[model.actuator_trnid[index.arm_actuators, 0]]
        # Six comparisons a period: on Python floats they cost a third of numpy's.
        lo, hi = (arm_range[:, 0] - LIMIT_SLACK).tolist(), (arm_range[:, 1] + LIMIT_SLACK).tolist()
        self._arm_bounds = list(zip(lo, hi, strict=True))
        self._pinned_at = index.tension_limit - 1e-6
        # Views where the addresses run in order (a read through them copies nothing).
        self._arm_q = _view(data.qpos, index.arm_qpos)
        self._tensions = _view(data.sensordata, index.tension_sensors)
        self.saturated_since = np.full(32, -1.0)
        self.saturation_logged = np.zeros(32, dtype=bool)
        self._tracking = False  # a tendon is pinned now, or one was logged and still is

    def check(self, time: float, happened: list[Happening]) -> str | None:
        """A fault message, or None; appends a ``warning`` for a tendon held at its limit."""
        ix = self.index
        # MuJoCo resets the state itself when it meets a bad qacc/qpos/qvel, and counts a
        # warning: a nonzero count is the divergence (the state is no longer the run's).
        now = self.data.time
        if now < self._due:
            for warning in self._divergence:
                if warning.number:
                    return "the physics diverged (MuJoCo reset an unstable state)"
        self._due = now + self._span
        for (lo, hi), angle in zip(self._arm_bounds, self._arm_q().tolist(), strict=True):
            if not lo <= angle <= hi:
                return self._beyond()
        # A tendon pinned at its limit is not a fault (a fist pressed into the palm does it),
        # but a researcher should know: log it once per episode.
        tensions = self._tensions()
        # The common case. The largest tension through argmax: numpy's max (its reduction
        # machinery) costs four times as much, and more just after a physics step.
        if not self._tracking and tensions.item(tensions.argmax()) < self._pinned_at:
            return None
        pinned = tensions >= self._pinned_at
        if not pinned.any() and not self.saturation_logged.any():
            self.saturated_since.fill(-1.0)
            self._tracking = False
            return None
        self._tracking = True
        self.saturated_since[~pinned] = -1.0
        self.saturated_since[pinned & (self.saturated_since < 0)] = time
        held = pinned & (time - self.saturated_since >= SATURATION_LIMIT_S)
        for k in np.flatnonzero(held & ~self.saturation_logged):
            joint = int(k) // 2
            message = (
                f"{FINGERS[joint // 4]} joint {joint % 4} "
                f"{'flexor' if k % 2 == 0 else 'extensor'} tendon held at its "
                f"{ix.tension_limit:g} N limit for {SATURATION_LIMIT_S:g} s"
            )
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

    def _beyond(self) -> str:
        """The fault message of the first arm joint beyond its limit."""
        q = self._arm_q().tolist()
        bounds = enumerate(zip(self._arm_bounds, q, strict=True))
        j = next(j for j, ((lo, hi), angle) in bounds if not lo <= angle <= hi)
        return f"PUMA joint {j + 1} is beyond its limit ({np.degrees(q[j]):.1f} deg)"


def _view(array: np.ndarray, index: np.ndarray) -> Callable[[], np.ndarray]:
    """A reader of ``array[index]``: a view when ``index`` runs in order, else a copy."""
    first = int(index[0])
    if np.array_equal(index, np.arange(first, first + len(index))):
        view = array[first : first + len(index)]
        return lambda: view
    return lambda: array[index]
