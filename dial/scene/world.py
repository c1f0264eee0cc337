"""World files: a scene's objects, hand poses, arm locations, arm programs and criteria.

Parsing is pure Python (``tomllib``); see ``docs/scenes.md`` for the format. Every problem
raises :class:`~dial.scene.reader.WorldFileError` naming the file and the key.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from difflib import get_close_matches
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal

from dial.instructions.limits import drive_problem, hand_problem
from dial.instructions.scene_names import SceneNames
from dial.instructions.types import FINGERS
from dial.scene.criteria import Criterion, parse_criterion
from dial.scene.mjcf import body_names
from dial.scene.objects import Prior, parse_objects
from dial.scene.reader import Reader, WorldFileError
from dial.scene.resolve import resolve_scene
from dial.scene.valii import NAME, Appro, Drive, Move, Statement, StatementError, parse_statement

JOINTS: tuple[str, ...] = ("abd", "mcp", "pip", "dip")  # joint j of a finger: bit 4*f + j
MAX_TURNS = 20.0  # a thread's turns before it lets go; more is a typo, not a bulb
AXES: tuple[str, ...] = ("object", "world")


@dataclass(frozen=True)
class HandPose:
    """A named hand pose: ``angles`` maps mask bit ``4*f + j`` to a joint angle in rad."""

    name: str
    angles: Mapping[int, float]

    @property
    def mask(self) -> int:
        """The 16-bit joint mask of the joints this pose sets."""
        return sum(1 << bit for bit in self.angles)


@dataclass(frozen=True)
class Location:
    """A tool-frame (``hand_palm`` site) target for the arm.

    ``pos`` (m) and ``rpy`` (rad; fixed-axis roll about x, then pitch about y, then yaw about
    z: R = Rz(yaw) Ry(pitch) Rx(roll)) are in the world frame when ``body`` is ``None``. With a
    body, they are in that body's frame (``axes == "object"``), or are a world-axes offset from
    the body's origin (``axes == "world"``: the location follows the body's position only, e.g.
    for a bulb that turns as it unscrews). ``rpy = (pi, 0, 0)`` points the tool z axis down.
    """

    name: str
    body: str | None
    pos: tuple[float, float, float]
    rpy: tuple[float, float, float]
    axes: Literal["object", "world"] = "object"

    @property
    def quat(self) -> tuple[float, float, float, float]:
        """``rpy`` as a unit quaternion (w, x, y, z)."""
        (cr, sr), (cp, sp), (cy, sy) = ((math.cos(a / 2), math.sin(a / 2)) for a in self.rpy)
        return (
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        )


@dataclass(frozen=True)
class Program:
    """A stored arm program; each statement keeps its line number within the program text."""

    name: str
    statements: tuple[Statement, ...]


@dataclass(frozen=True)
class World:
    """Everything a world file declares. ``objects`` maps aliases to MuJoCo body names;
    ``priors`` maps body names to what the file says is believed of them (if anything)."""

    name: str
    path: Path
    model_path: Path
    objects: Mapping[str, str]
    poses: Mapping[str, HandPose]
    locations: Mapping[str, Location]
    programs: Mapping[str, Program]
    criteria: tuple[Criterion, ...]
    thread_turns: float | None = None  # [thread] turns: the model's threads let go after these
    priors: Mapping[str, Prior] = field(default_factory=lambda: MappingProxyType({}))

    def scene_names(self) -> SceneNames:
        """The names the script checker needs."""
        return SceneNames(
            name=self.name,
            poses={name: pose.mask for name, pose in self.poses.items()},
            locations=frozenset(self.locations),
            programs=frozenset(self.programs),
            objects=frozenset(self.objects),
            anchored=frozenset(n for n, loc in self.locations.items() if loc.body is not None),
        )


_OPTIONAL_KEYS = ("poses", "locations", "programs", "criteria", "thread")


def load_world(path: Path) -> World:
    """Load and validate a world file (following ``extends``)."""
    path = path.resolve()
    data, _ = _load_merged(path, ())
    reader = Reader(path)
    reader.keys(data, "", ["scene", "objects"], _OPTIONAL_KEYS)
    scene = reader.table(data["scene"], "scene")
    reader.keys(scene, "scene", ["model"], ["poses", "description"])
    model_path = Path(reader.string(scene["model"], "scene.model"))
    if not model_path.is_file():
        raise reader.error("scene.model", f"no such model file: {model_path}")
    objects, priors = parse_objects(reader, data["objects"])
    poses: dict[str, HandPose] = {}
    if "poses" in scene:
        shared = Path(reader.string(scene["poses"], "scene.poses"))
        poses.update(_shared_poses(reader, shared))
    # The world file's poses win over the shared ones: a task tunes a standard pose (the
    # paper's "prelight") for its object under the standard name.
    for name, table in reader.table(data.get("poses", {}), "poses").items():
        poses[name] = parse_pose(reader, name, table)
    locations = {
        name: _location(reader, name, value, objects)
        for name, value in reader.table(data.get("locations", {}), "locations").items()
    }
    programs = {
        name: _program(reader, name, value, locations)
        for name, value in reader.table(data.get("programs", {}), "programs").items()
    }
    criteria = tuple(
        parse_criterion(reader, _name(reader, "criteria", name), value, objects)
        for name, value in reader.table(data.get("criteria", {}), "criteria").items()
    )
    return World(
        name=path.stem,
        path=path,
        model_path=model_path,
        objects=MappingProxyType(objects),
        poses=MappingProxyType(poses),
        locations=MappingProxyType(locations),
        programs=MappingProxyType(programs),
        criteria=criteria,
        thread_turns=_thread_turns(reader, data["thread"]) if "thread" in data else None,
        priors=MappingProxyType(priors),
    )


def load_scene_names(scene: str, script_dir: Path) -> SceneNames:
    """The :data:`~dial.instructions.scene_names.SceneLoader` for the script checker.

    Beyond the world file, it reads the model (without MuJoCo): a malformed model, or an
    object that names no body of it, is reported here rather than when a run starts.
    """
    world = load_world(resolve_scene(scene, script_dir))
    check_bodies(world)
    return world.scene_names()


def check_bodies(world: World) -> None:
    """Raise :class:`WorldFileError` if the model is malformed or lacks an object's body."""
    bodies = body_names(world.model_path)
    for alias, body in world.objects.items():
        if body not in bodies:
            close = get_close_matches(body, sorted(bodies), n=2)
            hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
            raise WorldFileError(
                world.path, f"objects.{alias}", f"no body '{body}' in {world.model_path.name}{hint}"
            )


def parse_pose(reader: Reader, name: str, table: Any) -> HandPose:
    """One pose: per finger, ``[abd, mcp, pip, dip]`` in degrees, or a table of some of them."""
    key = f"poses.{_name(reader, 'poses', name)}"
    table = reader.table(table, key)
    reader.keys(table, key, [], FINGERS)
    angles: dict[int, float] = {}
    for finger, value in table.items():
        fkey, base = f"{key}.{finger}", 4 * FINGERS.index(finger)
        if isinstance(value, list):
            joints = dict(zip(JOINTS, reader.vector(value, fkey, len(JOINTS)), strict=True))
        else:
            sub = reader.table(value, fkey)
            reader.keys(sub, fkey, [], JOINTS)
            joints = {j: reader.number(v, f"{fkey}.{j}") for j, v in sub.items()}
        for joint, deg in joints.items():
            problem = hand_problem(joint, math.radians(deg))
            if problem is not None:
                raise reader.error(f"{fkey}.{joint}", problem)
            angles[base + JOINTS.index(joint)] = math.radians(deg)
    if not angles:
        raise reader.error(key, f"a pose must set at least one joint of {', '.join(FINGERS)}")
    return HandPose(name, MappingProxyType(dict(sorted(angles.items()))))


def _shared_poses(world: Reader, path: Path) -> dict[str, HandPose]:
    data = _read_toml(path, world)
    reader = Reader(path)
    reader.keys(data, "", ["poses"], [])
    return {n: parse_pose(reader, n, t) for n, t in reader.table(data["poses"], "poses").items()}


def _location(reader: Reader, name: str, value: Any, objects: Mapping[str, str]) -> Location:
    key = f"locations.{_name(reader, 'locations', name)}"
    table = reader.table(value, key)
    reader.keys(table, key, ["pos", "rpy"], ["object", "axes"])
    body = None
    if "object" in table:
        body = objects[reader.choice(table["object"], f"{key}.object", objects, "object")]
    world_axes = reader.choice(table.get("axes", "object"), f"{key}.axes", AXES, "axes") == "world"
    if world_axes and body is None:
        raise reader.error(f"{key}.axes", "axes applies to object-relative locations only")
    x, y, z = reader.vector(table["pos"], f"{key}.pos", 3)
    roll, pitch, yaw = (math.radians(a) for a in reader.vector(table["rpy"], f"{key}.rpy", 3))
    return Location(name, body, (x, y, z), (roll, pitch, yaw), "world" if world_axes else "object")


def _program(reader: Reader, name: str, value: Any, locations: Mapping[str, Location]) -> Program:
    key = f"programs.{_name(reader, 'programs', name)}"
    text = reader.string(value, key)
    statements: list[Statement] = []
    for number, line in enumerate(text.splitlines(), start=1):
        where = f"{key} line {number}"
        try:
            statement = parse_statement(line, number)
        except StatementError as e:
            raise reader.error(where, str(e)) from None
        # A stored DRIVE turning further than its joint's whole range overshoots wherever it
        # starts (a session, such as dial teach, checks a drive against the joint's angle).
        if isinstance(statement, Drive) and (p := drive_problem(statement.joint, statement.angle)):
            raise reader.error(where, p)
        if isinstance(statement, Move | Appro) and statement.location not in locations:
            valid = ", ".join(locations) or "(none)"
            raise reader.error(
                where, f"unknown location '{statement.location}'; valid locations: {valid}"
            )
        if statement is not None:
            statements.append(statement)
    if not statements:
        raise reader.error(key, "a program needs at least one statement")
    return Program(name, tuple(statements))


def _thread_turns(reader: Reader, value: Any) -> float:
    """``[thread] turns``: counter-clockwise turns from screwed tight until the thread lets go."""
    table = reader.table(value, "thread")
    reader.keys(table, "thread", ["turns"], [])
    turns = reader.number(table["turns"], "thread.turns")
    if not 0.0 < turns <= MAX_TURNS:
        raise reader.error(
            "thread.turns", f"expected more than 0 and at most {MAX_TURNS:g}, got {turns:g}"
        )
    return turns


def _name(reader: Reader, table: str, name: str) -> str:
    if not NAME.match(name):
        raise reader.error(f"{table}.{name}", "invalid name: expected [A-Za-z_][A-Za-z0-9_]*")
    return name


def _load_merged(path: Path, seen: tuple[Path, ...]) -> tuple[dict[str, Any], frozenset[Path]]:
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
    data = _read_toml(path, Reader(seen[-1]) if seen else None)
    scene = data.get("scene")
    if isinstance(scene, dict):
        for key in ("model", "poses"):
            if isinstance(scene.get(key), str):
                scene[key] = str((path.parent / scene[key]).resolve())
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
        base, ancestry = _load_merged(base_path, (*seen, path))
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


def _read_toml(path: Path, referrer: Reader | None) -> dict[str, Any]:
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
