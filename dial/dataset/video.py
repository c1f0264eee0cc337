"""``--cameras``: each camera's frames rendered offscreen at the dataset's fps, encoded as an
h264 mp4 per episode (the ``video`` extra), with LeRobot's per-channel statistics.

A camera is ``task`` (the view of ``dial run --video``) or a camera of the scene's model.
The worker encodes; only the mp4's bytes travel to the parent.
"""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from dial.backend.driver import MujocoRobot
from dial.dataset.plan import CAMERA_SIZE
from dial.dataset.stats import QUANTILE_KEYS, QUANTILES
from dial.errors import DialError
from dial.recording.geometry import task_camera
from dial.recording.video import Renderer, VideoFile
from dial.scene.world import World

TASK = "task"
STATS_EVERY = 5  # frames between the frames the statistics are taken from
STATS_STRIDE = 4  # and the pixels: every 4th row and column


class Cameras:
    """Renders every named camera at each frame; ``close`` gives the mp4s' bytes."""

    def __init__(self, robot: MujocoRobot, world: World, names: Sequence[str], fps: int) -> None:
        model, self.data = robot.model, robot.data
        height, width = CAMERA_SIZE
        self.sizes = dict.fromkeys(names, CAMERA_SIZE)
        body = mujoco.mjtObj.mjOBJ_BODY
        bodies = [int(mujoco.mj_name2id(model, body, b)) for b in world.objects.values()]
        view = task_camera(robot.data, bodies)
        self.folder = tempfile.TemporaryDirectory(prefix="dial-cameras-")
        self.renderers: dict[str, Renderer] = {}
        self.files: dict[str, VideoFile] = {}
        self.samples: dict[str, list[NDArray[np.uint8]]] = {n: [] for n in names}
        self.frames = 0
        for name in names:
            renderer = self.renderers[name] = Renderer(model, view, width, height)
            if name != TASK:
                renderer.camera.type = mujoco.mjtCamera.mjCAMERA_FIXED
                camera = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, name)
                if camera < 0:  # checked before the run (dial.dataset.plan.check_cameras)
                    raise DialError(f"--cameras: the scene has no camera '{name}'")
                renderer.camera.fixedcamid = camera
            self.files[name] = VideoFile(self._path(name), fps)

    def _path(self, name: str) -> Path:
        return Path(self.folder.name) / f"{name}.mp4"

    def frame(self) -> None:
        for name, renderer in self.renderers.items():
            image = renderer.render(self.data)
            self.files[name].write(image)
            if self.frames % STATS_EVERY == 0:
                self.samples[name].append(np.array(image[::STATS_STRIDE, ::STATS_STRIDE]))
        self.frames += 1

    def close(self) -> dict[str, bytes]:
        """Finish the videos; the feature name -> the mp4's bytes."""
        videos = {}
        try:
            for name, file in self.files.items():
                file.close()
                videos[f"observation.images.{name}"] = self._path(name).read_bytes()
            for renderer in self.renderers.values():
                renderer.close()
        finally:
            self.folder.cleanup()
        return videos

    def stats(self) -> dict[str, dict[str, NDArray[Any]]]:
        """LeRobot's image statistics: per channel, in [0, 1], shaped (3, 1, 1)."""
        out: dict[str, dict[str, NDArray[Any]]] = {}
        for name, frames in self.samples.items():
            pixels = np.stack(frames).reshape(-1, 3).astype(np.float64) / 255.0
            stats: dict[str, NDArray[Any]] = {
                "min": pixels.min(axis=0),
                "max": pixels.max(axis=0),
                "mean": pixels.mean(axis=0),
                "std": pixels.std(axis=0),
            }
            for key, q in zip(QUANTILE_KEYS, np.quantile(pixels, QUANTILES, axis=0), strict=True):
                stats[key] = q
            shaped = {key: value.reshape(3, 1, 1) for key, value in stats.items()}
            shaped["count"] = np.array([len(frames)], dtype=np.int64)
            out[f"observation.images.{name}"] = shaped
        return out
