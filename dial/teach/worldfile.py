"""Writing taught names into a world file, keeping its comments, order and layout.

tomlkit edits the parsed document in place: an existing entry keeps its place and the
comments around it, a new location goes at the end of ``[locations]`` and a new pose after
the file's last ``[poses.NAME]``. The text is checked (it must load as a world file), written
to a temporary file beside the original and renamed over it, after the original is copied to
``FILE.bak``; a crash leaves either the old file or the new one, never half of one.
"""

from __future__ import annotations

import math
import os
import shutil
import tempfile
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import tomlkit
from tomlkit.items import InlineTable, Item, Table

from dial.errors import DialError
from dial.instructions.types import FINGERS
from dial.scene.reader import WorldFileError
from dial.scene.world import JOINTS, HandPose, Location, load_world
from dial.teach.frames import half_turn

POS_DIGITS = 4  # m: 0.1 mm
ANGLE_DIGITS = 1  # deg: 0.1 deg

TableName = Literal["poses", "locations"]


class WriteError(DialError):
    """The world file could not be written; the original is untouched."""


@dataclass(frozen=True)
class Taught:
    """One taught name as TOML text: ``items`` are (key, value) pairs in writing order.

    A location is one inline table (``{ object = "pitcher", pos = [...], rpy = [...] }``); a
    pose is one ``[poses.NAME]`` table with a key per finger.
    """

    table: TableName
    name: str
    items: tuple[tuple[str, str], ...]

    def text(self) -> str:
        """The entry as it appears in the file."""
        if self.table == "locations":
            return f"{self.name} = {inline_table(self.items)}"
        body = "".join(f"{k} = {v}\n" for k, v in self.items)
        return f"[poses.{self.name}]\n{body}"


def number(value: float, digits: int) -> str:
    """A rounded number as TOML: ``0.1234``, ``90``, never ``-0``."""
    x = round(value, digits) + 0.0
    return str(int(x)) if x == int(x) else f"{x:.{digits}f}".rstrip("0")


def toml_vector(values: Iterable[float], digits: int) -> str:
    return "[" + ", ".join(number(v, digits) for v in values) + "]"


def inline_table(items: Iterable[tuple[str, str]]) -> str:
    return "{ " + ", ".join(f"{k} = {v}" for k, v in items) + " }"


def location_entry(
    name: str,
    alias: str | None,
    body: str | None,
    pos: Iterable[float],
    rpy_deg: Iterable[float],
    world_axes: bool,
) -> tuple[Location, Taught]:
    """A location rounded to what is written (0.1 mm, 0.1 deg), and its TOML entry."""
    p = tuple(round(v, POS_DIGITS) for v in pos)
    r = tuple(half_turn(round(v, ANGLE_DIGITS)) for v in rpy_deg)
    items = [] if alias is None else [("object", f'"{alias}"')]
    items += [("pos", toml_vector(p, POS_DIGITS)), ("rpy", toml_vector(r, ANGLE_DIGITS))]
    if world_axes:
        items.append(("axes", '"world"'))
    rad = (math.radians(r[0]), math.radians(r[1]), math.radians(r[2]))
    location = Location(name, body, (p[0], p[1], p[2]), rad, "world" if world_axes else "object")
    return location, Taught("locations", name, tuple(items))


def pose_entry(name: str, angles_deg: dict[int, float]) -> tuple[HandPose, Taught]:
    """A pose of the joints in ``angles_deg`` (mask bit -> deg), rounded to 0.1 deg."""
    rounded = {bit: round(a, ANGLE_DIGITS) for bit, a in sorted(angles_deg.items())}
    items = []
    for f, finger in enumerate(FINGERS):
        joints = [(j, rounded[4 * f + j]) for j in range(4) if 4 * f + j in rounded]
        if len(joints) == 4:
            items.append((finger, toml_vector((a for _, a in joints), ANGLE_DIGITS)))
        elif joints:
            items.append(
                (finger, inline_table((JOINTS[j], number(a, ANGLE_DIGITS)) for j, a in joints))
            )
    pose = HandPose(name, {bit: math.radians(a) for bit, a in rounded.items()})
    return pose, Taught("poses", name, tuple(items))


def new_file_text(extends: str, scene: str, into: str) -> str:
    """The start of a world file made by ``dial teach --into``."""
    return (
        f"# Poses and locations taught with `dial teach --scene {scene} --into {into}`.\n"
        f"# Everything else comes from the world this file extends; see docs/teaching.md.\n"
        f"extends = {tomlkit.string(extends).as_string()}\n"
    )


def toml_item(text: str) -> Item:
    item = tomlkit.parse(f"v = {text}\n").item("v")  # keeps the layout of ``text``
    assert isinstance(item, Item)
    return item


def _blank_line(doc: tomlkit.TOMLDocument) -> None:
    """One blank line before a new table at the end of the file."""
    text = doc.as_string()
    if text and not text.endswith("\n\n"):
        doc.add(tomlkit.nl())


def _put_location(doc: tomlkit.TOMLDocument, entry: Taught) -> None:
    table = doc.get("locations")
    if table is None:
        table = tomlkit.table()
        _blank_line(doc)
        doc.add("locations", table)
    table[entry.name] = toml_item(inline_table(entry.items))


def _put_pose(doc: tomlkit.TOMLDocument, entry: Taught) -> None:
    poses = doc.get("poses")
    if poses is None:
        poses = tomlkit.table(is_super_table=True)
        _blank_line(doc)
        doc.add("poses", poses)
    existing = poses.get(entry.name)
    if isinstance(existing, Table):  # keep its place and comments; replace its fingers
        for finger in [k for k in existing if k not in dict(entry.items)]:
            del existing[finger]
        for key, text in entry.items:
            existing[key] = toml_item(text)
        return
    table = tomlkit.table()
    for key, text in entry.items:
        table.add(key, toml_item(text))
    table.add(tomlkit.nl())
    poses[entry.name] = table


def render(text: str, entries: Iterable[Taught]) -> str:
    """``text`` (a world file) with ``entries`` put into it."""
    doc = tomlkit.parse(text)
    for entry in entries:
        (_put_location if entry.table == "locations" else _put_pose)(doc, entry)
    out = doc.as_string()
    return out if out.endswith("\n") else out + "\n"


def write_world(path: Path, text: str) -> Path | None:
    """Check ``text`` loads as a world file, then replace ``path`` with it atomically.

    Returns the backup (``FILE.bak``, a copy of the previous file), or None for a new file.
    """
    fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    tmp = Path(tmp_name)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        try:  # relative paths resolve as they will for the real file
            load_world(tmp)
        except WorldFileError as e:
            raise WriteError(str(e).replace(str(tmp), str(path))) from None
        backup = None
        if path.exists():
            shutil.copymode(path, tmp)
            backup = path.with_name(path.name + ".bak")
            shutil.copy2(path, backup)
        os.replace(tmp, path)
        return backup
    except OSError as e:
        raise WriteError(f"cannot write {path}: {e.strerror or e}") from None
    finally:
        tmp.unlink(missing_ok=True)


def entry_names(doc_text: str, table: TableName) -> frozenset[str]:
    """The names a world file's text defines itself in ``table``."""
    value = tomlkit.parse(doc_text).get(table)
    if isinstance(value, Table | InlineTable):
        return frozenset(value.keys())
    return frozenset()
