"""A recording as rerun's own viewer shows it, without a display: screenshots for the tests
and the docs.

``python -m dial.recording.screenshot RUN.rrd SHOT.png [WIDTHxHEIGHT]`` runs
``rerun RUN.rrd --window-size WxH --screenshot-to SHOT.png`` in a virtual X server (Xvfb)
that renders with Mesa's software Vulkan (lavapipe): the whole viewer, its time cursor at the
end of the run. Linux only; Debian packages ``xvfb``, ``mesa-vulkan-drivers`` and
``libvulkan1``.

``python -m dial.recording.screenshot RUN.rrd SHOT.png --at SECONDS [--view NAME]`` shows one
view (default: the 3-D scene) at a simulated time instead. The ``rerun`` command cannot move
the time cursor, so this drives a headless viewer through rerun's experimental
``ViewerClient`` (rerun 0.41). The virtual screen is much larger than the
window, so that its pointer (at the screen's centre) is outside the window and no tooltip
covers the picture.
"""

from __future__ import annotations

import argparse
import ctypes.util
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

from dial.errors import DialError

SIZE = (1600, 1000)
TIMEOUT_S = 180.0
PORT = 9911  # the headless viewer's, away from rerun's default 9876
NOTICES_S = 12.0


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
        cmd = ["rerun", str(rrd), "--bind", "127.0.0.1", "--port", "0"]
        cmd += ["--window-size", f"{width}x{height}"]
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


def view_at(rrd: Path, png: Path, seconds: float, view: str = "scene") -> None:
    """Save the view named ``view`` of ``rrd`` at ``seconds`` of simulated time."""
    from rerun.experimental import ViewerClient

    client = ViewerClient.spawn(headless=True, port=PORT)
    try:
        client.open(str(rrd.resolve()))
        client.set_time("sim_time", duration=seconds, play_state="paused")
        time.sleep(NOTICES_S)  # wall time, for the picture only: start-up notices fade
        views = {v.name: v.view_id for v in client.get_state().views}
        if view not in views:
            raise DialError(f"no view '{view}' (views: {', '.join(sorted(views))})")
        client.save_screenshot(str(png.resolve()), view_id=views[view])
    finally:
        client.quit()


def main(argv: list[str]) -> None:
    ap = argparse.ArgumentParser(prog="python -m dial.recording.screenshot", description=__doc__)
    ap.add_argument("rrd", type=Path)
    ap.add_argument("png", type=Path)
    ap.add_argument("size", nargs="?", default="1600x1000", help="the window, WIDTHxHEIGHT")
    ap.add_argument("--at", type=float, help="one view at this simulated time (s)")
    ap.add_argument("--view", default="scene", help="with --at: the view's name")
    args = ap.parse_args(argv)
    if args.at is not None:
        view_at(args.rrd, args.png, args.at, args.view)
    else:
        width, height = (int(v) for v in args.size.split("x"))
        screenshot(args.rrd, args.png, (width, height))


if __name__ == "__main__":
    main(sys.argv[1:])
