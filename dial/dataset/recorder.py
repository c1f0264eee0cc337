"""The observer that samples a run into an :class:`~dial.dataset.episode.Episode`.

It samples on simulated time: frame ``k`` is the state after control period
``round(k * control_hz / fps)`` (exact when fps divides the control rate, 100 Hz; else
within half a period), so timestamps are exactly ``k / fps``. A frame's ``action`` is the
set-points applied in the period after it (what a policy seeing the frame should command);
the last frame's is the hold the run ends with. Like every observer it reads the physics
and never writes it: a run with a dataset gives the same log and final state as without.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from dial.dataset.episode import Episode, EpisodeInfo
from dial.dataset.features import DEFAULT_FPS, Features, features
from dial.dataset.robot import RobotReader, robot_names, scene_bodies
from dial.engine.observe import Watched
from dial.errors import DialError

if TYPE_CHECKING:
    from dial.dataset.video import Cameras
    from dial.engine.result import RunResult


def task_text(script: str, scene: str) -> str:
    """The task of an episode, as text: the script and the scene it ran in."""
    return f"{script} in scene {scene}"


class _Columns:
    """Arrays that grow by doubling, one per feature; row ``k`` is frame ``k``."""

    def __init__(self, spec: Features) -> None:
        self.spec = {n: f for n, f in spec.items() if f.dtype != "video"}
        self.rows = 0
        self.arrays: dict[str, NDArray[np.generic]] = {
            name: np.zeros((256, *_frame_shape(f.shape)), dtype=f.dtype)
            for name, f in self.spec.items()
        }

    def next_row(self) -> int:
        k = self.rows
        if k == len(next(iter(self.arrays.values()))):
            self.arrays = {n: np.concatenate([a, np.zeros_like(a)]) for n, a in self.arrays.items()}
        self.rows += 1
        return k

    def trimmed(self) -> dict[str, NDArray[np.generic]]:
        return {n: a[: self.rows].copy() for n, a in self.arrays.items()}


def _frame_shape(shape: tuple[int, ...]) -> tuple[int, ...]:
    return () if shape == (1,) else shape


class Recorder:
    """Samples a run at ``fps`` frames per simulated second; ``episode`` holds the result
    once the run has ended (None if it could not finish, or was interrupted)."""

    what = "the dataset recorder"  # how messages name it

    def __init__(
        self,
        script: str,
        fps: int = DEFAULT_FPS,
        cameras: Sequence[str] = (),
        perturb_mm: float | None = None,
    ) -> None:
        """``script`` names the run in its task and metadata; ``perturb_mm`` is the run's
        ``--perturb`` (None: the length of the shift the log's ``scene`` record gives,
        which the log rounds to a micrometre)."""
        self.script, self.fps, self.camera_names = script, fps, tuple(cameras)
        self.perturb_mm = perturb_mm
        self.episode: Episode | None = None
        self.cameras: Cameras | None = None

    def begin(self, run: Watched) -> None:
        robot = run.robot
        self.scene = run.world.name
        self.bodies = scene_bodies(list(run.world.objects.values()))
        self.reader = RobotReader(robot, self.bodies)
        self.hz = round(1.0 / robot.period)
        if not 1 <= self.fps <= self.hz:
            raise DialError(f"--fps must be from 1 to {self.hz}, got {self.fps}")
        # The periods before the first frame: a resumed run's episode starts where it resumes.
        self.start = robot.steps // robot.substeps
        if self.camera_names:
            from dial.dataset.video import Cameras

            self.cameras = Cameras(robot, run.world, self.camera_names, self.fps)
        sizes = {} if self.cameras is None else self.cameras.sizes
        self.names = robot_names(robot.index.profile)
        self.spec = features(self.names, self.bodies, sizes, self.fps)
        self.columns = _Columns(self.spec)
        scene = run.log.of("scene")
        self.seed = int(scene[-1].get("seed", 0)) if scene else 0  # type: ignore[call-overload]
        shift = scene[-1].get("perturb") if scene else None
        self.shift = (
            tuple(float(x) * 1000 for x in shift) if isinstance(shift, list) else (0.0,) * 3
        )
        self.pending: int | None = None  # the frame whose action the next period gives
        self.frames = 0
        self._sample()

    def _perturb_mm(self) -> float:
        if self.perturb_mm is not None:
            return float(self.perturb_mm)
        return round(float(np.linalg.norm(self.shift)), 3)

    def _due(self, frame: int) -> int:
        """The control period after which frame ``frame`` is taken (rounded half up)."""
        return (2 * frame * self.hz + self.fps) // (2 * self.fps)

    def period(self, periods: int, tick: int) -> None:
        if self.pending is not None:
            self.columns.arrays["action"][self.pending] = self.reader.commanded()
            self.pending = None
        if periods - self.start >= self._due(self.frames):
            self._sample()

    def _sample(self) -> None:
        r = self.reader
        k = self.columns.next_row()
        arrays = self.columns.arrays
        arrays["observation.state"][k] = r.state()
        arrays["observation.velocity"][k] = r.velocity()
        arrays["observation.joint_load"][k] = r.joint_load()
        arrays["observation.tactile"][k] = r.tactile_depths().reshape(
            arrays["observation.tactile"].shape[1:]
        )
        pose = np.empty(7 * r.poses)
        r.environment(pose)
        arrays["observation.environment_state"][k] = pose
        if self.cameras is not None:
            self.cameras.frame()
        self.pending = k
        self.frames += 1

    def end(self, result: RunResult | None) -> None:
        videos = {} if self.cameras is None else self.cameras.close()
        if result is None or result.summary.interrupted is not None:
            return
        arrays = self.columns.arrays
        if self.pending is not None:  # the last frame: the hold the run ends with
            arrays["action"][self.pending] = self.reader.commanded()
        done = arrays["next.done"]
        done[self.frames - 1] = True
        arrays["next.success"][self.frames - 1] = result.ok
        s = result.summary
        info = EpisodeInfo(
            script=self.script,
            scene=self.scene,
            tick=s.tick_length,
            seed=self.seed,
            perturb_mm=self._perturb_mm(),
            shift_mm=(round(self.shift[0], 3), round(self.shift[1], 3), round(self.shift[2], 3)),
            disturbances=tuple(result.disturbances),
            outcomes=dict(s.outcomes),
            success=result.ok,
            criteria=dict(result.success),
            error=result.error,
            sim_time=s.sim_time,
        )
        self.episode = Episode(
            self.fps,
            {n: f.as_json() for n, f in self.spec.items()},
            self.columns.trimmed(),
            task_text(self.script, self.scene),
            info,
            videos,
            {} if self.cameras is None else self.cameras.stats(),
            self.names.robot_type,
        )
