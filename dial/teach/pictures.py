"""Pictures of a scene: ``dial world --picture`` (named frames) and ``dial teach --snapshot``.

MuJoCo renders the scene offscreen (``MUJOCO_GL=egl`` on Linux without a display); the frames
and labels are drawn over the image with matplotlib (the optional ``plot`` extra), after
projecting them with the same free camera.
"""

from __future__ import annotations

import importlib.util
import math
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dial.errors import DialError
from dial.geometry import location_pose
from dial.recording.geometry import Camera, task_camera
from dial.recording.video import Renderer
from dial.robot.snapshot import FloatArray
from dial.teach.sim import Sim

WIDTH, HEIGHT = 1280, 960  # --picture
AXIS = 0.05  # m: the length of a drawn frame axis
AZIMUTH, ELEVATION = 135.0, -32.0  # deg: from the front right of the table, above it
GHOST = 0.25  # the robot's opacity in --picture, so that frames behind it show
COLOURS = ("#e41a1c", "#2ca02c", "#1f5fd6")  # x, y, z
EXTRA = "pip install 'dial[plot]'"


def plot_problem(flag: str) -> str | None:
    """Why ``flag`` cannot draw here (a usage error), or None."""
    if importlib.util.find_spec("matplotlib") is None:
        return f"{flag} needs the optional 'plot' extra (matplotlib): {EXTRA}"
    return None


def project(camera: Camera, fovy_deg: float, size: tuple[int, int], points: Any) -> FloatArray:
    """Pixel coordinates (N, 2) of world points (N, 3) in a (width, height) image of
    MuJoCo's free camera; points behind the camera get NaN."""
    az, el = math.radians(camera.azimuth), math.radians(camera.elevation)
    forward = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    v = np.asarray(points, dtype=np.float64) - np.asarray(camera.position())
    x, y, z = v @ right, v @ up, v @ forward
    width, height = size
    focal = height / 2 / math.tan(math.radians(fovy_deg) / 2)
    z = np.where(z > 1e-6, z, np.nan)
    return np.stack([width / 2 + focal * x / z, height / 2 - focal * y / z], axis=1)


def _fit_camera(points: FloatArray, fovy: float, size: tuple[int, int]) -> Camera:
    """The task camera's direction, backed off until every point is inside the picture."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = tuple(float(c) for c in (lo + hi) / 2)
    camera = Camera((centre[0], centre[1], centre[2]), 0.8, AZIMUTH, ELEVATION)
    margin = np.array([0.08 * size[0], 0.08 * size[1]])
    for _ in range(40):
        px = project(camera, fovy, size, points)
        inside = np.all(np.isfinite(px)) and np.all((px >= margin) & (px <= size - margin))
        if inside:
            break
        camera = Camera(camera.lookat, camera.distance * 1.1, camera.azimuth, camera.elevation)
    return camera


def _figure(image: Any) -> tuple[Any, Any]:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    height, width = image.shape[:2]
    fig = Figure(figsize=(width / 100, height / 100), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.imshow(image)
    ax.set_xlim(0, width)
    ax.set_ylim(height, 0)
    ax.axis("off")
    return fig, ax


def _overlap(a: Sequence[float], b: Sequence[float]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


Box = tuple[float, float, float, float]  # x0, y0, x1, y1 in pixels


def _place(boxes: list[Box], x: float, y: float, w: float, h: float) -> tuple[float, float]:
    """A free spot for a w x h label near (x, y): tried below, then above, further each time."""
    for k in range(60):
        dy = (k // 2 + 1) * (h + 2) * (1 if k % 2 else -1) if k else 0
        box = (x, y + dy, x + w, y + dy + h)
        if not any(_overlap(b, box) for b in boxes):
            boxes.append(box)
            return box[0], box[1]
    return x, y


def world_picture(sim: Sim, path: Path) -> int:
    """Render ``sim``'s scene with every location as a labelled frame; returns how many."""
    world, believed = sim.world, sim.ctx.believed
    frames = {n: location_pose(world, believed, n) for n in world.locations}
    objects = {a: believed[b] for a, b in world.objects.items()}
    points = np.array([p for p, _ in (*frames.values(), *objects.values())])
    fovy = float(sim.model.vis.global_.fovy)
    camera = _fit_camera(points, fovy, (WIDTH, HEIGHT))
    image, depth = _render(sim, camera)
    fig, ax = _figure(image)
    boxes: list[Box] = []
    for name, (pos, rot) in frames.items():
        ends = np.vstack([pos, pos + AXIS * rot.T])  # origin, then the x, y, z axis tips
        px = project(camera, fovy, (WIDTH, HEIGHT), ends)
        hidden = _hidden(camera, depth, pos, px[0])
        for k in range(3):
            ax.plot(
                *px[[0, k + 1]].T,
                color=COLOURS[k],
                linewidth=1.6 if hidden else 2.2,
                linestyle=(0, (2, 2)) if hidden else "-",
            )
        _label(ax, boxes, px[0], f"{name} (hidden)" if hidden else name, "black", "white")
    for alias, (pos, _) in objects.items():
        px = project(camera, fovy, (WIDTH, HEIGHT), pos[None])[0]
        _label(ax, boxes, px, f"[{alias}]", "white", "#444444")
    ax.text(
        12,
        24,
        f"{world.name}: locations (x red, y green, z blue; {AXIS * 1000:g} mm)",
        fontsize=13,
        color="black",
        backgroundcolor="white",
    )
    _save(fig, path)
    return len(frames)


def _render(sim: Sim, camera: Camera) -> tuple[Any, FloatArray]:
    """The scene with the robot see-through, and the depth (m) of the scene without it, so
    that a frame behind an object can be told from one behind the robot."""
    model, robot = sim.model, sim.parts.robot  # this model copy is only drawn from now on
    mats = np.unique(model.geom_matid[robot])
    mats = mats[mats >= 0]
    alpha = model.geom_rgba[robot, 3].copy(), model.mat_rgba[mats, 3].copy()
    renderer = Renderer(model, camera, WIDTH, HEIGHT)
    try:
        model.geom_rgba[robot, 3], model.mat_rgba[mats, 3] = 0.0, 0.0  # not drawn at all
        renderer.renderer.enable_depth_rendering()
        depth = np.asarray(renderer.render(sim.data), dtype=np.float64)
        renderer.renderer.disable_depth_rendering()
        model.geom_rgba[robot, 3], model.mat_rgba[mats, 3] = alpha[0] * GHOST, alpha[1] * GHOST
        return renderer.render(sim.data), depth
    finally:
        renderer.close()


def _hidden(camera: Camera, depth: FloatArray, pos: FloatArray, px: FloatArray) -> bool:
    """Whether the scene (not the robot) hides the point ``pos`` drawn at pixel ``px``."""
    col, row = round(float(px[0])), round(float(px[1]))
    if not (0 <= row < depth.shape[0] and 0 <= col < depth.shape[1]):
        return False
    az, el = math.radians(camera.azimuth), math.radians(camera.elevation)
    forward = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    along = float((pos - np.asarray(camera.position())) @ forward)
    return bool(depth[row, col] < along - 0.01)


def _label(ax: Any, boxes: list[Box], origin: Sequence[float], text: str, fg: str, bg: str) -> None:
    w, h = 7.2 * len(text) + 8, 17.0
    x, y = _place(boxes, origin[0] + 10, origin[1] - h - 4, w, h)
    if abs(y - (origin[1] - h - 4)) > 1:  # moved off its frame: a leader line back to it
        ax.plot([origin[0], x], [origin[1], y + h / 2], color="#555555", linewidth=0.8)
    ax.text(
        x + 4,
        y + h / 2,
        text,
        fontsize=10,
        color=fg,
        va="center",
        bbox={"facecolor": bg, "edgecolor": "#555555", "alpha": 0.85, "pad": 2},
    )


def _save(fig: Any, path: Path) -> None:
    try:
        fig.savefig(path)
    except OSError as e:
        raise DialError(f"cannot write {path}: {e.strerror or e}") from None


class Snapshots:
    """``dial teach --snapshot DIR``: a PNG of the scene after every command that ran."""

    def __init__(self, sim: Sim, directory: Path) -> None:
        try:
            directory.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            message = f"--snapshot: cannot make the folder {directory}: {e.strerror or e}"
            raise DialError(message) from None
        self.sim, self.directory, self.count = sim, directory, 0
        bodies = [sim.model.body(b).id for b in sim.world.objects.values()]
        self.renderer = Renderer(sim.model, task_camera(sim.data, bodies))

    def __call__(self, line: str) -> None:
        self.count += 1
        slug = re.sub(r"[^A-Za-z0-9_.-]+", "_", line)[:40].strip("_")
        fig, ax = _figure(self.renderer.render(self.sim.data))
        ax.text(8, 18, line, fontsize=11, color="black", backgroundcolor="white")
        _save(fig, self.directory / f"{self.count:03d}-{slug}.png")

    def close(self) -> None:
        self.renderer.close()
