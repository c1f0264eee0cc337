"""World files' ``extends``: merging a world file with the ones it extends, entry by entry.

Pure Python; every problem raises :class:`~dial.scene.reader.WorldFileError` naming the file
and the key.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from dial.scene.reader import Reader, WorldFileError
from dial.scene.resolve import ROBOT_FILE, resolve_scene


def load_merged(path: Path, seen: tuple[Path, ...]) -> tuple[dict[str, Any], frozenset[Path]]:
    """The file's data with ``extends`` applied, and every file that went into it.

    Tables merge entry by entry, the child winning. ``extends`` names one world file or a
    list of them, merged in order. An entry that two bases set differently is an error
    unless the child sets it too, or the later base extends the earlier one (a refinement):
    a silent winner would hide which definition a script gets. ``[scene] description`` is
    only text and never conflicts. Paths in ``[scene]`` are made absolute against the file
    that wrote them, so a world file may extend one in another directory (or a bundled
    scene, by name).
    """
    reader = Reader(path)
    if path in seen:
        chain = " -> ".join(str(p) for p in (*seen, path))
        raise reader.error("extends", f"extends cycle: {chain}")
    data = read_toml(path, Reader(seen[-1]) if seen else None)
    scene = data.get("scene")
    if isinstance(scene, dict):
        for key in ("model", "poses"):
            if isinstance(scene.get(key), str):
                scene[key] = str((path.parent / scene[key]).resolve())
    robot = data.get("robot")
    if isinstance(robot, str) and (path.parent / robot / ROBOT_FILE).is_file():
        data["robot"] = str((path.parent / robot).resolve())  # a folder, not a bundled name
    if "extends" not in data:
        return data, frozenset({path})
    value = data.pop("extends")
    names = [value] if isinstance(value, str) else value
    if not isinstance(names, list) or not names or not all(isinstance(n, str) for n in names):
        raise reader.error("extends", "expected a world file (name or path) or a list of them")
    merged: dict[str, Any] = {}
    files = {path}
    setter: dict[tuple[str, ...], Path] = {}  # each base entry -> the base that set it
    mine = _leaves(data)
    for name in names:
        try:
            base_path = resolve_scene(name, path.parent).resolve()
        except LookupError as e:
            raise reader.error("extends", str(e)) from None
        base, ancestry = load_merged(base_path, (*seen, path))
        before = _leaves(merged)
        for entry, leaf in _leaves(base).items():
            clash = entry in before and before[entry] != leaf and entry not in mine
            if clash and entry != ("scene", "description") and setter[entry] not in ancestry:
                raise reader.error(
                    ".".join(entry),
                    f"set differently by {setter[entry].name} and {base_path.name}; "
                    "set it in this file to choose",
                )
            setter[entry] = base_path
        merged = _merge(merged, base)
        files |= ancestry
    return _merge(merged, data), frozenset(files)


def _leaves(data: Mapping[str, Any]) -> dict[tuple[str, ...], Any]:
    """Every entry of a world file (``("poses", "grip")``, ``("scene", "model")``), by key."""
    out: dict[tuple[str, ...], Any] = {}
    for key, value in data.items():
        if isinstance(value, dict):
            out.update({(key, name): entry for name, entry in value.items()})
        else:
            out[(key,)] = value
    return out


def _merge(base: dict[str, Any], child: Mapping[str, Any]) -> dict[str, Any]:
    """Tables merge entry by entry; an entry (a pose, a location, a criterion) is replaced
    whole, so a redefined location does not keep, say, the ``object`` of the one it replaces."""
    out = dict(base)
    for key, value in child.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = {**out[key], **value}
        else:
            out[key] = value
    return out


def read_toml(path: Path, referrer: Reader | None) -> dict[str, Any]:
    try:
        with path.open("rb") as f:
            return tomllib.load(f)
    except FileNotFoundError:
        if referrer is not None:
            raise referrer.error("", f"no such file: {path}") from None
        raise WorldFileError(path, "", "no such file") from None
    except tomllib.TOMLDecodeError as e:
        raise WorldFileError(path, "", f"invalid TOML: {e}") from None
    except UnicodeDecodeError as e:
        raise WorldFileError(path, "", f"not UTF-8 text (byte {e.start}); TOML is UTF-8") from None
    except OSError as e:
        raise WorldFileError(path, "", f"cannot read it: {e.strerror or e}") from None
