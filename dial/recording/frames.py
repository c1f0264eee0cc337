"""Decimated frames of a run: what a recording shows over time, buffered as arrays.

A frame is copied out of ``MjData`` (a few small array copies, no rerun calls), so sampling
during a run is cheap; the buffer is handed to the sink in batches.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from dial.backend.model import RobotIndex, hand_angles, tactile_images, tendon_tensions
from dial.recording.geometry import moving_bodies
from dial.recording.task import TaskProbe
from dial.robot.snapshot import FloatArray
from dial.robots.profile import RobotProfile

RECORD_HZ = 50.0  # frames per second of simulated time in a recording


@dataclass(frozen=True)
class Batch:
    """``n`` frames: ``time_ns`` (n,) simulated ns; ``tick`` (n,); body poses in the world,
    ``pos`` (n, B, 3) m and ``quat`` (n, B, 4) (x, y, z, w) for the bodies ``Frames.bodies``;
    ``joints`` (n, 16) rad, mask order; ``arm`` (n, A) rad, the arm's joints in order;
    ``tensions`` (n, L) the hand's load readings (a tendon hand: its 32 tensions in N, tendon
    order; else its joints' torques, N m); ``tactile`` (n, fingers, rows, columns) m; ``task``
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

    def __init__(
        self,
        model: mujoco.MjModel,
        probe: TaskProbe | None = None,
        profile: RobotProfile | None = None,
    ) -> None:
        self.index = ix = RobotIndex.from_model(model, profile)
        self.probe = probe
        self.bodies = moving_bodies(model)
        rows, cols = ix.profile.hand.taxels
        self._tactile_shape = (len(ix.fingertip_sites), rows, cols)
        loads = len(ix.load_sensors) or len(ix.hand_actuators)
        # Where each field ends in a frame's flat row.
        arm = 16 + len(ix.arm_qpos)
        self._ends = (16, arm, arm + loads, arm + loads + int(np.prod(self._tactile_shape)))
        self._rows: list[tuple[int, int, FloatArray, FloatArray, FloatArray]] = []

    def capture(
        self, time: float, tick: int, data: mujoco.MjData, tensions: FloatArray | None = None
    ) -> None:
        """Copy one frame; ``tensions`` replaces the load sensors' (a replay has no forces)."""
        ix = self.index
        tactile = tactile_images(data, ix).ravel()
        self._rows.append(
            (
                round(time * 1e9),
                tick,
                data.xpos[self.bodies].copy(),
                data.xquat[self.bodies].copy(),
                np.concatenate(
                    [
                        hand_angles(data, ix),
                        data.qpos[ix.arm_qpos],
                        tendon_tensions(data, ix) if tensions is None else tensions,
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
        hand, arm, loads, tactile = self._ends
        return Batch(
            time_ns=np.array([r[0] for r in rows], dtype=np.int64),
            tick=np.array([r[1] for r in rows], dtype=np.int64),
            pos=np.stack([r[2] for r in rows]),
            quat=quat[..., [1, 2, 3, 0]],  # MuJoCo's (w, x, y, z) to rerun's (x, y, z, w)
            joints=flat[:, :hand],
            arm=flat[:, hand:arm],
            tensions=flat[:, arm:loads],
            tactile=flat[:, loads:tactile].reshape(-1, *self._tactile_shape),
            task=flat[:, tactile:],
        )

    def __len__(self) -> int:
        return len(self._rows)
