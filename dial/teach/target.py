"""The world file a teaching session writes, and which new names it may take.

Without ``--into`` the session writes the scene's own world file. With ``--into FILE`` it
writes FILE, which is created (when it does not exist) to ``extends`` the scene's world. A
name that a shared file defines (the shared hand poses, or a world the target extends) is
refused: defining it in the target would silently change it for every script of that world.
A name the target defines itself is replaced only when asked (``replace``).
"""

from __future__ import annotations

import dataclasses
import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from dial.errors import DialError
from dial.scene.resolve import bundled_name, resolve_scene
from dial.scene.world import World, load_world
from dial.teach.worldfile import TableName, Taught, entry_names, new_file_text

TABLES: tuple[TableName, ...] = ("poses", "locations")


class NameClash(DialError):
    """A new name is already taken; the message says by what and what to do."""


@dataclass(frozen=True)
class Target:
    """The file ``write`` writes: its path, current text, and where taken names come from."""

    path: Path
    text: str  # the file's text now (for a file to be created: the text it starts with)
    exists: bool
    own: frozenset[tuple[str, str]]  # (table, name) the file defines itself
    shared: Mapping[tuple[str, str], str]  # (table, name) -> which shared file defines it


def open_target(scene: str, into: str | None, cwd: Path) -> tuple[World, Target]:
    """The session's world and target for ``dial teach --scene scene [--into into]``."""
    scene_path = resolve_scene(scene, cwd).resolve()
    scene_world = load_world(scene_path)
    if into is None:
        return scene_world, _existing(scene_path)
    path = (cwd / into).resolve()
    if path.is_file():
        world = load_world(path)
        if world.model_path != scene_world.model_path:
            raise DialError(
                f"--into {into}: it is a world of {world.model_path.name}, "
                f"not of scene {scene} ({scene_world.model_path.name})"
            )
        return world, _existing(path)
    if not path.parent.is_dir():
        raise DialError(f"--into {into}: no such directory {path.parent}")
    bundled = bundled_name(scene_path) is not None and not Path(scene).suffix
    extends = scene if bundled else os.path.relpath(scene_path, path.parent)
    text = new_file_text(extends, scene, path.name)
    shared = _shared(scene_path, path)
    world = dataclasses.replace(scene_world, name=path.stem, path=path)
    return world, Target(path, text, False, frozenset(), shared)


def _existing(path: Path) -> Target:
    text = path.read_text(encoding="utf-8")
    own = frozenset((t, n) for t in TABLES for n in entry_names(text, t))
    shared = {k: v for k, v in _shared(path, path).items() if k not in own}
    return Target(path, text, True, own, shared)


def _shared(path: Path, target: Path) -> dict[tuple[str, str], str]:
    """Every pose and location name of the files ``path`` uses, by the file that defines it."""
    out: dict[tuple[str, str], str] = {}
    _walk(path, target, out, set())
    return out


def _walk(path: Path, target: Path, out: dict[tuple[str, str], str], seen: set[Path]) -> None:
    if path in seen:  # load_world has already refused cycles; this only stops the walk
        return
    seen.add(path)
    with path.open("rb") as f:
        data: dict[str, Any] = tomllib.load(f)
    poses = data.get("scene", {}).get("poses")
    if isinstance(poses, str):
        shared = (path.parent / poses).resolve()
        with shared.open("rb") as f:
            for name in tomllib.load(f).get("poses", {}):
                out[("poses", name)] = f"the shared hand poses ({shared.name})"
    bases = data.get("extends", [])
    for base in [bases] if isinstance(bases, str) else bases:
        _walk(resolve_scene(base, path.parent).resolve(), target, out, seen)
    if path != target:
        what = f"{path.name}, which {target.name} extends"
        for table in TABLES:
            for name in data.get(table, {}):
                out[(table, name)] = what


def check_name(
    target: Target, saved: tuple[Taught, ...], table: TableName, name: str, replace: bool
) -> str:
    """Raise :class:`NameClash` if ``name`` may not be saved; else a note on what it replaces."""
    kind = table.removesuffix("s")
    if any(e.table == table and e.name == name for e in saved):
        if not replace:
            raise NameClash(
                f"{kind} '{name}' was saved in this session already; add 'replace' to save it again"
            )
        return f" (replaces the {kind} saved before)"
    if (table, name) in target.own:
        if not replace:
            raise NameClash(
                f"{kind} '{name}' is already defined in {target.path.name}; add 'replace' to "
                f"overwrite it (write keeps the old file as {target.path.name}.bak)"
            )
        return f" (replaces the {kind} of {target.path.name})"
    origin = target.shared.get((table, name))
    if origin is not None:
        raise NameClash(
            f"{kind} '{name}' is defined in {origin}: a {kind} of that name in "
            f"{target.path.name} would change it for every script of this world; "
            f"choose another name"
        )
    return ""
