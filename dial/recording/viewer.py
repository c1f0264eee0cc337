"""``--viewer``: MuJoCo's passive viewer, following the run in real time.

The viewer runs in its own thread and copies the simulation at each ``sync``; the run paces
itself to wall-clock time (``--realtime``), which never changes results. Dragging a body with
the mouse in the viewer does push on it, though: a run watched that way is not reproducible.
"""

from __future__ import annotations

import os
import sys
from typing import Any

from dial.engine import RunResult, Watched
from dial.engine.observe import every, first_line
from dial.errors import DialError
from dial.recording.geometry import task_camera
from dial.recording.observers import object_bodies

VIEWER_HZ = 60.0  # screen updates per second of simulated (here also wall-clock) time


def require_display(flag: str, instead: str = "--record FILE.rrd or --video FILE.mp4") -> None:
    """Raise a one-line :class:`DialError` where a window cannot open (no X11 or Wayland);
    ``instead``: the command's options that need no display."""
    if sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    ):
        raise DialError(
            f"{flag} needs a display, and neither DISPLAY nor WAYLAND_DISPLAY is set; "
            f"use {instead} instead"
        )


def _probe_glfw() -> None:
    """Fail with one line where GLFW cannot start: MuJoCo's viewer would exit the process."""
    import glfw

    reporting, glfw.ERROR_REPORTING = glfw.ERROR_REPORTING, "ignore"
    try:
        if not glfw.init():
            display = os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
            raise DialError(f"--viewer could not open a window on display '{display}'")
        glfw.terminate()  # the viewer starts it again, in its own thread
    finally:
        glfw.ERROR_REPORTING = reporting


class PassiveViewer:
    what = "MuJoCo's viewer"  # how messages name it

    def begin(self, run: Watched) -> None:
        _probe_glfw()
        import mujoco.viewer

        model, data = run.robot.model, run.robot.data
        try:
            self.handle: Any = mujoco.viewer.launch_passive(
                model, data, show_left_ui=False, show_right_ui=False
            )
        except Exception as e:  # GLFW and GL failures come as assorted errors
            raise DialError(f"--viewer could not open MuJoCo's viewer: {first_line(e)}") from e
        camera = task_camera(data, object_bodies(model, list(run.world.objects.values())))
        with self.handle.lock():
            self.handle.cam.lookat[:] = camera.lookat
            self.handle.cam.distance = camera.distance
            self.handle.cam.azimuth = camera.azimuth
            self.handle.cam.elevation = camera.elevation
        self.every = every(VIEWER_HZ, run.robot.period)

    def period(self, periods: int, tick: int) -> None:
        # A closed window ends the watching, not the run.
        if periods % self.every == 0 and self.handle.is_running():
            self.handle.sync()

    def show_now(self) -> None:
        """A paused run: show this moment."""
        if self.handle.is_running():
            self.handle.sync()

    def end(self, result: RunResult | None) -> None:
        self.handle.close()
