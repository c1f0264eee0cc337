"""``--video``: render a run offscreen with MuJoCo's renderer and encode it with imageio.

imageio (with its ffmpeg plugin, whose wheel ships an ffmpeg binary) is the optional
``video`` extra; :func:`video_problem` says what is missing before a run starts. On Linux
without a display, MuJoCo renders through EGL on the CPU (``MUJOCO_GL=egl``, which the
command line sets before MuJoCo is imported).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

import mujoco

from dial.engine import RunResult, Watched
from dial.engine.observe import every, first_line
from dial.errors import DialError
from dial.recording.geometry import Camera, task_camera
from dial.recording.observers import object_bodies

VIDEO_FPS = 25.0  # frames per second of simulated time: a whole 4 control periods per frame
WIDTH, HEIGHT = 640, 480  # MuJoCo's default offscreen buffer
SUFFIXES = (".mp4", ".gif")
EXTRA = "pip install 'dial[video]'"


def video_problem(path: str) -> str | None:
    """Why ``--video path`` cannot work here (a usage error), or None."""
    suffix = Path(path).suffix.lower()
    if suffix not in SUFFIXES:
        return f"--video writes {' or '.join(SUFFIXES)} files, not '{suffix or path}'"
    needed = ["imageio"] + (["imageio_ffmpeg"] if suffix == ".mp4" else [])
    missing = [m for m in needed if importlib.util.find_spec(m) is None]
    if missing:
        return f"--video needs the optional 'video' extra ({', '.join(missing)}): {EXTRA}"
    return None


class Renderer:
    """Frames of the scene from a fixed camera, as (height, width, 3) uint8 RGB arrays."""

    def __init__(
        self, model: mujoco.MjModel, camera: Camera, width: int = WIDTH, height: int = HEIGHT
    ) -> None:
        # A frame larger than the model's offscreen buffer needs a larger buffer.
        model.vis.global_.offwidth = max(int(model.vis.global_.offwidth), width)
        model.vis.global_.offheight = max(int(model.vis.global_.offheight), height)
        try:
            self.renderer = mujoco.Renderer(model, height, width)
        except Exception as e:  # the GL backends raise assorted errors
            raise DialError(
                f"cannot render offscreen ({first_line(e)}); on Linux without a display, "
                "set MUJOCO_GL=egl"
            ) from e
        # Shadows and reflections triple the cost of a frame on a CPU renderer.
        self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
        self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
        self.camera = mujoco.MjvCamera()
        self.camera.lookat[:] = camera.lookat
        self.camera.distance = camera.distance
        self.camera.azimuth = camera.azimuth
        self.camera.elevation = camera.elevation

    def render(self, data: mujoco.MjData) -> Any:
        self.renderer.update_scene(data, self.camera)
        return self.renderer.render()

    def close(self) -> None:
        self.renderer.close()


class VideoWriter:
    """Writes a frame every ``1 / fps`` s of simulated time (rounded to whole periods)."""

    what = "the video writer"  # how messages name it

    def __init__(self, path: Path, fps: float = VIDEO_FPS) -> None:
        self.path, self.fps = path, fps

    def begin(self, run: Watched) -> None:
        model, data = run.robot.model, run.robot.data
        self.data = data
        self.every = every(self.fps, run.robot.period)
        fps = 1.0 / (self.every * run.robot.period)
        objects = object_bodies(model, list(run.world.objects.values()))
        self.renderer = Renderer(model, task_camera(data, objects))
        try:
            self.writer = VideoFile(self.path, fps)
        except Exception:
            self.renderer.close()
            raise
        self._frame()

    def period(self, periods: int, tick: int) -> None:
        if periods % self.every == 0:
            self._frame()

    def _frame(self) -> None:
        self.writer.write(self.renderer.render(self.data))

    def end(self, result: RunResult | None) -> None:
        self.writer.close()
        self.renderer.close()


class VideoFile:
    """imageio's ffmpeg writer (mp4) or its pillow writer (gif), behind one interface."""

    def __init__(self, path: Path, fps: float) -> None:
        self.gif = path.suffix.lower() == ".gif"
        self.ms = 1000.0 / fps
        try:
            if self.gif:
                import imageio.v3 as iio

                self.file: Any = iio.imopen(path, "w", plugin="pillow")
            else:
                import imageio.v2 as iio2

                self.file = iio2.get_writer(
                    path, fps=fps, codec="libx264", macro_block_size=16, ffmpeg_log_level="error"
                )
        except OSError as e:
            raise DialError(f"--video cannot write '{path}': {first_line(e)}") from e

    def write(self, frame: Any) -> None:
        if self.gif:
            self.file.write(frame, duration=self.ms, loop=0)
        else:
            self.file.append_data(frame)

    def close(self) -> None:
        self.file.close()
