"""A recording as rerun's own viewer shows it, without a display: a screenshot for tests
and docs.

``python -m dial.recording.screenshot RUN.rrd SHOT.png [WIDTHxHEIGHT]`` runs
``rerun RUN.rrd --window-size WxH --screenshot-to SHOT.png`` in a virtual X server (Xvfb)
that renders with Mesa's software Vulkan (lavapipe). Linux only; Debian packages ``xvfb``,
``mesa-vulkan-drivers`` and ``libvulkan1``. The virtual screen is much larger than the
window, so that its pointer (at the screen's centre) is outside the window and no tooltip
covers the picture.
"""

from __future__ import annotations

import ctypes.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

from dial.errors import DialError

SIZE = (1600, 1000)
TIMEOUT_S = 180.0


def missing() -> str | None:
    """Why a screenshot cannot be taken here, or None."""
    if not sys.platform.startswith("linux"):
        return "screenshots use Xvfb, which is Linux only"
    for tool in ("Xvfb", "rerun"):
        if shutil.which(tool) is None:
            return f"'{tool}' is not installed"
    if ctypes.util.find_library("vulkan") is None:
        return "no Vulkan loader (libvulkan1)"
    return None


def screenshot(rrd: Path, png: Path, size: tuple[int, int] = SIZE) -> None:
    """Open ``rrd`` in rerun's viewer at ``size`` (logical pixels) and save what it shows."""
    why = missing()
    if why is not None:
        raise DialError(f"cannot take a screenshot: {why}")
    width, height = size
    read, write = os.pipe()
    xvfb = subprocess.Popen(  # the pointer, at the screen's centre, is outside the window
        ["Xvfb", "-displayfd", str(write), "-screen", "0", f"{5 * width}x{2 * height}x24"],
        pass_fds=(write,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(write)
    try:
        with os.fdopen(read) as fd:
            display = ":" + fd.readline().strip()
        env = {**os.environ, "DISPLAY": display}
        env.pop("WAYLAND_DISPLAY", None)
        cmd = ["rerun", str(rrd), "--port", "0", "--window-size", f"{width}x{height}"]
        done = subprocess.run(
            [*cmd, "--screenshot-to", str(png)],
            env=env,
            capture_output=True,
            text=True,
            timeout=TIMEOUT_S,
        )
        if done.returncode != 0 or not png.is_file():
            raise DialError(f"rerun took no screenshot: {done.stderr.strip()[-500:]}")
    finally:
        xvfb.terminate()
        xvfb.wait()


if __name__ == "__main__":
    arguments = sys.argv[1:]
    if len(arguments) not in (2, 3):
        sys.exit("usage: python -m dial.recording.screenshot RUN.rrd SHOT.png [WIDTHxHEIGHT]")
    w, h = (int(v) for v in (arguments[2] if len(arguments) == 3 else "1600x1000").split("x"))
    screenshot(Path(arguments[0]), Path(arguments[1]), (w, h))
