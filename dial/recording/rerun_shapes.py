"""MuJoCo geoms as rerun archetypes (for :mod:`dial.recording.rerun_sink`)."""

from __future__ import annotations

from typing import Any

import numpy as np
import rerun as rr

from dial.recording.geometry import Shape
from dial.robot.snapshot import FloatArray

SOLID = rr.components.FillMode.Solid


def rgba(rgba: FloatArray) -> np.ndarray:
    return np.asarray(np.round(np.clip(rgba, 0.0, 1.0) * 255), dtype=np.uint8)


def quat(wxyz: FloatArray) -> rr.Quaternion:
    """MuJoCo's (w, x, y, z) as rerun's quaternion, stored (x, y, z, w)."""
    return rr.Quaternion(xyzw=[wxyz[1], wxyz[2], wxyz[3], wxyz[0]])


def archetype(shape: Shape) -> Any:
    """The shape as a solid rerun archetype, in its own colour."""
    color = rgba(shape.rgba)
    r, half = float(shape.size[0]), float(shape.size[1])
    if shape.kind == "box":
        return rr.Boxes3D(half_sizes=[shape.size], colors=color, fill_mode=SOLID)
    if shape.kind in ("sphere", "ellipsoid"):
        size = [r, r, r] if shape.kind == "sphere" else shape.size
        return rr.Ellipsoids3D(half_sizes=[size], colors=color, fill_mode=SOLID)
    if shape.kind == "capsule":  # rerun's capsule starts at the origin; MuJoCo's is centred
        return rr.Capsules3D(
            lengths=[2 * half],
            radii=[r],
            translations=[[0.0, 0.0, -half]],
            colors=color,
            fill_mode=SOLID,
        )
    if shape.kind == "cylinder":
        return rr.Cylinders3D(lengths=[2 * half], radii=[r], colors=color, fill_mode=SOLID)
    assert shape.vertices is not None and shape.faces is not None
    return rr.Mesh3D(
        vertex_positions=shape.vertices, triangle_indices=shape.faces, albedo_factor=color
    )
