"""Disturbances during a run (DESIGN 2.8): pushes on bodies and sensor dropouts.

Each begins and ends at a physics step (its time rounded to the timestep), and the driver
steps one physics step at a time through a period where one does, so that when it acts
does not depend on the control period. A push sets ``xfrc_applied`` (world-frame force
at the body's centre of mass). A dropout masks the readings of one finger's sensor in
the snapshots and in the guard and monitor tests: tactile depths read 0, tendon
differentials read 0 (no load), joint angles read their set-points (no position error).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from dial.disturb import Disturbance, DisturbanceError, Dropout, Push
from dial.robot.protocol import Happening


@dataclass(frozen=True)
class _Window:
    item: Disturbance
    begin: int  # first physics step it acts in
    end: int | None  # first step it no longer acts in; None: to the end
    body: int  # body id of a push; -1 for a dropout


def body_choices(model: mujoco.MjModel) -> list[str]:
    """Names a push may name: every named body but the world."""
    names = (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in range(1, model.nbody))
    return sorted(n for n in names if n)


class Disturbances:
    """The disturbances of one run, on one model, in the order they were given."""

    def __init__(self, windows: tuple[_Window, ...] = ()) -> None:
        self.windows = windows
        self._boundaries = sorted({w.begin for w in windows} | {w.end for w in windows if w.end})
        self._active: list[_Window] = []
        self.dropped: frozenset[tuple[str, int]] = frozenset()  # (sensor, finger) out now

    @classmethod
    def none(cls) -> Disturbances:
        return cls()

    @classmethod
    def on(cls, model: mujoco.MjModel, items: Sequence[Disturbance]) -> Disturbances:
        """Place ``items`` on ``model``'s physics steps; an unknown body is an error that
        lists the valid ones."""
        dt = float(model.opt.timestep)
        windows = []
        for item in items:
            body = -1
            if isinstance(item, Push):
                body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, item.body)
                if body <= 0:
                    raise DisturbanceError(
                        f"--disturb '{item.text}': no body '{item.body}' in this scene; "
                        f"valid bodies: {', '.join(body_choices(model))}"
                    )
            until = item.until
            end = None if until is None else round(until / dt)
            windows.append(_Window(item, round(item.at / dt), end, body))
        return cls(tuple(windows))

    def resume_at(self, step: int) -> None:
        """Take up the disturbances acting at ``step`` (a run resumed from a state file; the
        forces are in the saved physics already)."""
        self._active = [
            w for w in self.windows if w.begin < step and (w.end is None or step < w.end)
        ]
        self._set_dropped()

    def _set_dropped(self) -> None:
        self.dropped = frozenset(
            (w.item.sensor, w.item.finger) for w in self._active if isinstance(w.item, Dropout)
        )

    def due(self, step: int, substeps: int) -> bool:
        """Whether one begins or ends within the next ``substeps`` physics steps."""
        if not self._boundaries:  # the common case: no --disturb
            return False
        return any(step <= b < step + substeps for b in self._boundaries)

    def apply(self, step: int, data: mujoco.MjData, happened: list[Happening], t: float) -> None:
        """Begin and end what is due at this physics step (before it is taken)."""
        if step not in self._boundaries:
            return
        for w in self.windows:
            if w.end == step and w in self._active:
                self._active.remove(w)
                happened.append(_record(w, "end", t, step))
            if w.begin == step and (w.end is None or w.end > step):
                self._active.append(w)
                happened.append(_record(w, "begin", t, step))
        pushed = [w for w in self.windows if isinstance(w.item, Push)]
        for body in {w.body for w in pushed}:
            force = np.zeros(3)
            for w in self._active:
                if w.body == body and isinstance(w.item, Push):
                    force += w.item.force
            data.xfrc_applied[body, :3] = force
        self._set_dropped()


def _record(w: _Window, phase: str, t: float, step: int) -> Happening:
    return Happening("disturb", {"what": w.item.text, "phase": phase, "t": t, "step": step})
