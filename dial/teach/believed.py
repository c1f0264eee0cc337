"""``dial run --save-world F.toml``: the believed world at the end of a run, as a world file.

The file is the run's world file with its ``[objects]`` entries replaced by tables that say
what the world model believes of each object (``{ body = ..., pos = [...], rpy = [...],
size = [...] }``, see :mod:`dial.scene.objects`); every other line, comment and table is
kept, as ``dial teach`` keeps them (:mod:`dial.teach.worldfile`). Paths that the world file
gives relative to itself (``extends``, ``[scene] model`` and ``poses``) are rewritten
relative to the new file, so that it loads from wherever it is written: ``dial world
F.toml`` shows it, and a script run in it starts from what the last run learned.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path

import tomlkit
from tomlkit.items import Table

from dial.scene.world import World
from dial.teach.frames import half_turn
from dial.teach.worldfile import (
    ANGLE_DIGITS,
    POS_DIGITS,
    inline_table,
    toml_item,
    toml_vector,
    write_world,
)

Entries = Mapping[str, Mapping[str, object]]  # body -> pos (m), rpy (deg), size (m)


def believed_text(world: World, believed: Entries, target: Path, note: str) -> str:
    """The text of ``world``'s file with every object as ``believed`` has it, for ``target``."""
    doc = tomlkit.parse(world.path.read_text(encoding="utf-8"))
    _relocate(doc, world.path.parent, target.resolve().parent)
    objects = doc.get("objects")
    if not isinstance(objects, Table):  # the objects come from the file it extends
        objects = tomlkit.table()
        doc.add("objects", objects)
    for alias, body in world.objects.items():
        objects[alias] = toml_item(inline_table(_items(body, believed[body])))
    text = doc.as_string()
    return f"# {note}\n" + (text if text.endswith("\n") else text + "\n")


def save_world(world: World, believed: Entries, target: Path, note: str) -> None:
    """Write the believed world to ``target`` (checked to load; the old file kept as .bak)."""
    write_world(target, believed_text(world, believed, target, note))


def _items(body: str, entry: Mapping[str, object]) -> list[tuple[str, str]]:
    pos = [float(v) for v in entry["pos"]]  # type: ignore[attr-defined]
    rpy = [half_turn(round(float(v), ANGLE_DIGITS)) for v in entry["rpy"]]  # type: ignore[attr-defined]
    items = [("body", tomlkit.string(body).as_string())]
    items += [("pos", toml_vector(pos, POS_DIGITS)), ("rpy", toml_vector(rpy, ANGLE_DIGITS))]
    size = entry.get("size")
    if size is not None:
        half = [float(v) for v in size]  # type: ignore[attr-defined]
        if all(math.isfinite(v) and v > 0 for v in half):  # a world file's size is all three
            items.append(("size", toml_vector(half, POS_DIGITS)))
    return items


def _relocate(doc: tomlkit.TOMLDocument, source: Path, target: Path) -> None:
    """Rewrite the file's own relative paths for a file in ``target`` instead of ``source``."""
    if source.resolve() == target:
        return
    extends = doc.get("extends")
    if isinstance(extends, str):
        doc["extends"] = _moved(extends, source, target)
    elif isinstance(extends, list):
        doc["extends"] = [_moved(str(name), source, target) for name in extends]
    scene = doc.get("scene")
    if isinstance(scene, Table):
        for key in ("model", "poses"):
            if isinstance(scene.get(key), str):
                scene[key] = _moved(str(scene[key]), source, target)


def _moved(name: str, source: Path, target: Path) -> str:
    """A path relative to ``source`` as one relative to ``target``; a bundled scene's name
    (not a file next to ``source``) as it is."""
    path = Path(name).expanduser()
    full = path if path.is_absolute() else source / path
    if not full.is_file():
        return name
    try:
        return Path(os.path.relpath(full.resolve(), target)).as_posix()
    except ValueError:  # another drive (Windows)
        return str(full.resolve())
