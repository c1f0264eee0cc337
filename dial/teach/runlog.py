"""``dial world --believed LOG.jsonl``: from a run's log, each object's believed pose beside its
true pose, and every change the world model made (docs/teaching.md).

A run whose world model changed (a grasp carried an object, ``locate`` or a fit measured one)
ends its log with a ``world`` record: believed and true poses at the end. A run without one
believed what its world file says throughout; its true poses are then those at the start
(the model's, moved by ``--perturb``), because the log does not say where free objects went.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from dial.backend.model import load_model, profile_at
from dial.geometry import matrix_rpy
from dial.recording.timeline import read_log
from dial.scene.belief import initial
from dial.scene.resolve import bundled_world, worlds_dir
from dial.scene.world import World, load_world
from dial.teach.describe import columns
from dial.teach.frames import deg_text, mm_text


def believed_from_log(path: Path) -> str:
    """The text ``dial world --believed`` prints for the log at ``path``."""
    records = read_log(path)  # checked: a 'scene' record first, known records well typed
    scene = records[0]
    world = load_world(_world_path(str(scene["world"])))
    shift = [float(v) for v in scene.get("perturb", [0.0, 0.0, 0.0])]
    lines = [
        f"run log {path}: scene {scene['scene']} ({scene['world']}), objects displaced by "
        f"{mm_text(shift)} mm (seed {scene.get('seed', 0)})",
        "",
    ]
    final = next((r for r in reversed(records) if r.get("kind") == "world"), None)
    if final is not None:
        lines.append("objects at the end of the run (pos mm, rpy deg; size: half-sizes mm)")
        lines += columns([_row(alias, entry) for alias, entry in final["objects"].items()])
    else:
        lines.append(
            "objects (the world model did not change in this run: believed as at load; true "
            "at the start, moved by --perturb; pos mm, rpy deg)"
        )
        lines += columns(_at_start(world, np.array(shift)))
    updates = [r for r in records if r.get("kind") == "belief"]
    lines += ["", "belief updates (pos mm; size: half-sizes mm)"]
    lines += columns([_update(r) for r in updates])
    return "\n".join(lines) + "\n"


def _world_path(world: str) -> Path:
    """The world file a ``scene`` record names: a bundled file's name, else its path."""
    path = Path(world)
    if path.is_absolute():
        return path
    # "pour.toml" is the default robot's; "allegro_panda/pour.toml" another bundled robot's.
    return bundled_world(world.removesuffix(".toml")) or worlds_dir() / path


def _cells(entry: Mapping[str, Any]) -> list[str]:
    """pos, rpy and size (if any) of a believed or true pose, as columns."""
    out = [f"pos {mm_text(entry['pos'])}", f"rpy {deg_text(entry['rpy'])}"]
    size = entry.get("size")
    out.append("" if size is None else f"size {_mm(size)}")
    return out


def _mm(values: Any) -> str:
    """``[x, y, z]`` mm from m; an unknown (null, NaN) value as ``?``."""
    return mm_text(math.nan if v is None else v for v in values).replace("nan", "?")


def _row(alias: str, entry: Mapping[str, Any]) -> list[str]:
    believed, true = entry["believed"], entry["true"]
    held = "held" if believed.get("held") else ""
    return [
        alias,
        str(entry["body"]),
        "believed",
        *_cells(believed),
        held,
        "true",
        *_cells(true)[:2],
        f"off {float(entry['off']) * 1000:.1f} mm",
    ]


def _at_start(world: World, shift: np.ndarray) -> list[list[str]]:
    """Believed (as at load) and true (the model's pose, perturbed) rows of every object."""
    model = load_model(world.model_path, profile_at(world.robot))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    poses = {}
    for body in world.objects.values():
        b = model.body(body).id
        poses[body] = (data.xpos[b].copy(), data.xmat[b].reshape(3, 3).copy())
    believed, sizes = initial(world, poses)
    rows = []
    for alias, body in world.objects.items():
        pos, rot = believed[body]
        entry: dict[str, Any] = {"pos": pos, "rpy": matrix_rpy(rot)}
        if body in sizes:
            entry["size"] = sizes[body]
        true = {"pos": poses[body][0] + shift, "rpy": matrix_rpy(poses[body][1])}
        off = float(np.linalg.norm(pos - true["pos"])) * 1000
        cells = [*_cells(entry), "true", *_cells(true)[:2], f"off {off:.1f} mm"]
        rows.append([alias, body, "believed", *cells])
    return rows


def _update(r: Mapping[str, Any]) -> list[str]:
    before, after = r["before"], r["after"]
    return [
        f"t={float(r['t']):.2f} s",
        f"tick {r.get('tick', '-')}",
        str(r["object"]),
        str(r["why"]),
        f"pos {mm_text(before['pos'])} -> {mm_text(after['pos'])}",
        "" if after.get("size") is None else f"size {_mm(after['size'])}",
    ]
