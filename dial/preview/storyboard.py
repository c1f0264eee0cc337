"""``dial preview --storyboard``: one panel per previewed block, the robot at the block's end.

MuJoCo renders each panel offscreen from the camera of ``dial run --video`` (``MUJOCO_GL=egl``
on Linux without a display); matplotlib (the optional ``plot`` extra) draws the tool's path
through the block over it, the caption, and tiles the panels.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from dial.errors import DialError
from dial.preview.scene import Scene
from dial.preview.walk import Panel
from dial.recording.geometry import Camera, task_camera
from dial.recording.observers import object_bodies
from dial.recording.video import Renderer
from dial.teach.pictures import project

COLUMNS = 4
GAP, TITLE, CAPTION = 8, 44, 46  # pixels: between panels, above them all, under each
LEGEND = (
    "the robot at the end of each block, in the order previewed; orange: the tool's path "
    "through the block (o: its start)"
)
PATH_COLOUR = "#ff7f0e"
PROBLEM_COLOUR = "#d62728"
FONT = 8  # points, at 100 dpi: about 5 pixels a character


def _size(count: int) -> tuple[int, int]:
    """A panel's pixels: smaller as there are more of them."""
    if count <= 8:
        return 480, 360
    if count <= 32:
        return 360, 270
    return 280, 210


def draw(scene: Scene, panels: Sequence[Panel], path: Path, title: str) -> int:
    """Render ``panels`` into one PNG at ``path``; returns how many."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    width, height = _size(len(panels))
    cols = min(COLUMNS, max(1, len(panels)))
    rows = max(1, math.ceil(len(panels) / cols))
    fw = max(cols * (width + GAP) + GAP, 480)
    legend = textwrap.wrap(LEGEND, fw // 7)
    head = TITLE + 14 * (len(legend) - 1)
    fh = head + rows * (height + CAPTION + GAP)
    fig = Figure(figsize=(fw / 100, fh / 100), dpi=100)
    FigureCanvasAgg(fig)
    fig.text(GAP / fw, 1 - 18 / fh, f"{title}: dial preview", fontsize=13, weight="bold")
    fig.text(GAP / fw, 1 - 24 / fh, "\n".join(legend), fontsize=FONT + 1, va="top")
    model, data = scene.model, scene.data
    fovy = float(model.vis.global_.fovy)
    camera = _camera(scene, panels, fovy, (width, height))
    renderer = Renderer(model, camera, width, height)
    try:
        for i, panel in enumerate(panels):
            row, col = divmod(i, cols)
            left = GAP + col * (width + GAP)
            top = head + row * (height + CAPTION + GAP)
            ax = fig.add_axes((left / fw, 1 - (top + height) / fh, width / fw, height / fh))
            data.qpos[:] = panel.qpos
            mujoco.mj_forward(model, data)
            ax.imshow(renderer.render(data))
            _overlay(ax, panel, project(camera, fovy, (width, height), panel.trace))
            ax.set_xlim(0, width)
            ax.set_ylim(height, 0)
            ax.axis("off")
            text = _caption(i + 1, panel, width // 6)
            fig.text(left / fw, 1 - (top + height + 4) / fh, text, fontsize=FONT, va="top")
    finally:
        renderer.close()
    try:
        fig.savefig(path)
    except OSError as e:
        raise DialError(f"cannot write the storyboard {path}: {e.strerror or e}") from None
    return len(panels)


def _camera(scene: Scene, panels: Sequence[Panel], fovy: float, size: tuple[int, int]) -> Camera:
    """The video's camera direction, on the objects and the tool's paths, as close as fits."""
    m, d = scene.model, scene.data
    objects = object_bodies(m, list(scene.world.objects.values()))
    points = np.vstack([d.xpos[objects], *(p.trace for p in panels)])
    base = task_camera(d, objects)
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = (lo + hi) / 2
    lookat = (float(centre[0]), float(centre[1]), float(centre[2]))
    camera = Camera(lookat, 0.5, base.azimuth, base.elevation)
    for _ in range(30):  # back off until the points are inside the middle of the picture
        px = project(camera, fovy, size, points)
        margin = 0.15 * np.array(size)
        if np.all(np.isfinite(px)) and np.all((px >= margin) & (px <= size - margin)):
            break
        camera = Camera(lookat, camera.distance * 1.1, camera.azimuth, camera.elevation)
    return camera


def _overlay(ax: Any, panel: Panel, pixels: Any) -> None:
    """The tool's path over the picture, and how many problems the block has."""
    pixels = pixels[np.all(np.isfinite(pixels), axis=1)]
    if len(pixels) >= 2:
        ax.plot(*pixels.T, color=PATH_COLOUR, linewidth=1.6)
        ax.plot(*pixels[0], marker="o", color=PATH_COLOUR, markersize=6, fillstyle="none")
        ax.plot(*pixels[-1], marker="o", color=PATH_COLOUR, markersize=4)
    if panel.problems:
        ax.text(
            6,
            6,
            f"{panel.problems} problem{'s' if panel.problems != 1 else ''}",
            color="white",
            fontsize=FONT + 1,
            va="top",
            bbox={"facecolor": PROBLEM_COLOUR, "edgecolor": "none", "pad": 2},
        )


def _caption(number: int, panel: Panel, chars: int) -> str:
    """Three lines at most: the block and its events; the path to it; how it ended."""
    place = panel.place.rsplit("/", 1)[-1]
    head = textwrap.shorten(f"{number}. {place}: {', '.join(panel.events)}", chars)
    where = " ".join(x for x in (panel.label.rstrip(" /"), panel.note) if x)
    tail = textwrap.wrap(where, chars, max_lines=2, placeholder=" ...") if where else []
    return "\n".join([head, *tail])
