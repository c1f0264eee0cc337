"""Decimated frames of a run: what a recording shows over time, buffered as arrays.

A frame is copied out of ``MjData`` (a few small array copies, no rerun calls), so sampling
during a run is cheap; the buffer is handed to the sink in batches.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from dial.backend.model import RobotIndex
from dial.recording.geometry import moving_bodies
from dial.recording.task import TaskProbe
from dial.robot.snapshot import FloatArray

RECORD_HZ = 50.0  # frames per second of simulated time in a recording


@dataclass(frozen=True)
class Batch:
    """``n`` frames: ``time_ns`` (n,) simulated ns; ``tick`` (n,); body poses in the world,
    ``pos`` (n, B, 3) m and ``quat`` (n, B, 4) (x, y, z, w) for the bodies ``Frames.bodies``;
    ``joints`` (n, 16) rad, mask order; ``arm`` (n, 6) rad, PUMA joints 1-6; ``tensions``
    (n, 32) N, tendon order; ``tactile`` (n, 4, 16, 16) m, finger, row, column; ``task``
    (n, S) the task's measurements (:class:`~dial.recording.task.TaskProbe`)."""

    time_ns: np.ndarray
    tick: np.ndarray
    pos: FloatArray
    quat: FloatArray
    joints: FloatArray
    arm: FloatArray
    tensions: FloatArray
    tactile: FloatArray
    task: FloatArray

    def __len__(self) -> int:
        return len(self.time_ns)


class Frames:
    """Collects frames from ``MjData`` until :meth:`take` hands them over."""

    def __init__(self, model: mujoco.MjModel, probe: TaskProbe | None = None) -> None:
        self.index = RobotIndex.from_model(model)
        self.probe = probe
        self.bodies = moving_bodies(model)
        self._tactile = [int(a) for a in self.index.tactile_sensors]
        self._rows: list[tuple[int, int, FloatArray, FloatArray, FloatArray]] = []

    def capture(
        self, time: float, tick: int, data: mujoco.MjData, tensions: FloatArray | None = None
    ) -> None:
        """Copy one frame; ``tensions`` (32,) N replaces the sensors' (a replay has no forces)."""
        ix, sd = self.index, data.sensordata
        tactile = np.concatenate([sd[a : a + 256] for a in self._tactile])
        self._rows.append(
            (
                round(time * 1e9),
                tick,
                data.xpos[self.bodies].copy(),
                data.xquat[self.bodies].copy(),
                np.concatenate(
                    [
                        data.qpos[ix.hand_qpos],
                        data.qpos[ix.arm_qpos],
                        sd[ix.tension_sensors] if tensions is None else tensions,
                        tactile,
                        self.probe.sample(data) if self.probe is not None else (),
                    ]
                ),
            )
        )

    def take(self) -> Batch | None:
        """The frames since the last call, as arrays; None when there are none."""
        if not self._rows:
            return None
        rows, self._rows = self._rows, []
        quat = np.stack([r[3] for r in rows])
        flat = np.stack([r[4] for r in rows])
        return Batch(
            time_ns=np.array([r[0] for r in rows], dtype=np.int64),
            tick=np.array([r[1] for r in rows], dtype=np.int64),
            pos=np.stack([r[2] for r in rows]),
            quat=quat[..., [1, 2, 3, 0]],  # MuJoCo's (w, x, y, z) to rerun's (x, y, z, w)
            joints=flat[:, :16],
            arm=flat[:, 16:22],
            tensions=flat[:, 22:54],
            tactile=flat[:, 54:1078].reshape(-1, 4, 16, 16),
            task=flat[:, 1078:],
        )

    def __len__(self) -> int:
        return len(self._rows)
