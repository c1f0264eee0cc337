"""World files: a scene's objects, hand poses, arm locations, arm programs and criteria.

Parsing is pure Python (``tomllib``); see ``docs/scenes.md`` for the format. Every problem
raises :class:`~dial.scene.reader.WorldFileError` naming the file and the key.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from difflib import get_close_matches
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal

from dial.errors import DialError
from dial.instructions.limits import drive_problem, hand_problem
from dial.instructions.scene_names import SceneNames
from dial.instructions.types import FINGERS
from dial.robots.facts import RobotFacts, robot_facts
from dial.scene.criteria import Criterion, parse_criterion
from dial.scene.merge import load_merged, read_toml
from dial.scene.mjcf import body_names
from dial.scene.objects import Prior, parse_objects
from dial.scene.reader import Reader, WorldFileError
from dial.scene.resolve import (
    ROBOT_DIR,
    ROBOT_FILE,
    bundled_name,
    bundled_robot_names,
    models_dir,
    resolve_scene,
)
from dial.scene.valii import NAME, Appro, Drive, Move, Statement, StatementError, parse_statement

JOINTS: tuple[str, ...] = ("abd", "mcp", "pip", "dip")  # joint j of a finger: bit 4*f + j
MAX_TURNS = 20.0  # a thread's turns before it lets go; more is a typo, not a bulb
AXES: tuple[str, ...] = ("object", "world")


def default_robot() -> Path:
    """The folder of the robot a world file runs on when it names none."""
    return (models_dir() / ROBOT_DIR).resolve()


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
    ``robot`` is the folder of the robot the scene binds scripts to (``robot = ...``, by
    default the Utah hand on the PUMA); ``priors`` maps body names to what the file says is
    believed of them (if anything)."""

    name: str
    path: Path
    model_path: Path
    objects: Mapping[str, str]
    poses: Mapping[str, HandPose]
    locations: Mapping[str, Location]
    programs: Mapping[str, Program]
    criteria: tuple[Criterion, ...]
    thread_turns: float | None = None  # [thread] turns: the model's threads let go after these
    robot: Path = field(default_factory=default_robot)  # the robot's folder (robot.toml)
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
            robot=robot_facts(self.robot),
        )


_OPTIONAL_KEYS = ("robot", "poses", "locations", "programs", "criteria", "thread")


def load_world(path: Path) -> World:
    """Load and validate a world file (following ``extends``)."""
    path = path.resolve()
    data, _ = load_merged(path, ())
    reader = Reader(path)
    reader.keys(data, "", ["scene", "objects"], _OPTIONAL_KEYS)
    scene = reader.table(data["scene"], "scene")
    reader.keys(scene, "scene", ["model"], ["poses", "description"])
    model_path = Path(reader.string(scene["model"], "scene.model"))
    if not model_path.is_file():
        raise reader.error("scene.model", f"no such model file: {model_path}")
    objects, priors = parse_objects(reader, data["objects"])
    folder = _robot(reader, data["robot"]) if "robot" in data else default_robot()
    robot = _facts(reader, folder)
    poses: dict[str, HandPose] = {}
    if "poses" in scene:
        shared = Path(reader.string(scene["poses"], "scene.poses"))
        poses.update(_shared_poses(reader, shared, robot))
    # The world file's poses win over the shared ones: a task tunes a standard pose (the
    # paper's "prelight") for its object under the standard name.
    for name, table in reader.table(data.get("poses", {}), "poses").items():
        poses[name] = parse_pose(reader, name, table, robot)
    locations = {
        name: _location(reader, name, value, objects)
        for name, value in reader.table(data.get("locations", {}), "locations").items()
    }
    programs = {
        name: _program(reader, name, value, locations, robot)
        for name, value in reader.table(data.get("programs", {}), "programs").items()
    }
    # `NAME = false` drops a criterion that an extended world file declares.
    criteria = tuple(
        parse_criterion(reader, _name(reader, "criteria", name), value, objects)
        for name, value in reader.table(data.get("criteria", {}), "criteria").items()
        if value is not False
    )
    return World(
        name=bundled_name(path) or path.stem,
        path=path,
        model_path=model_path,
        objects=MappingProxyType(objects),
        poses=MappingProxyType(poses),
        locations=MappingProxyType(locations),
        programs=MappingProxyType(programs),
        criteria=criteria,
        thread_turns=_thread_turns(reader, data["thread"]) if "thread" in data else None,
        robot=folder,
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
    bodies = body_names(world.model_path, world.robot)
    for alias, body in world.objects.items():
        if body not in bodies:
            close = get_close_matches(body, sorted(bodies), n=2)
            hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
            raise WorldFileError(
                world.path, f"objects.{alias}", f"no body '{body}' in {world.model_path.name}{hint}"
            )


def parse_pose(reader: Reader, name: str, table: Any, robot: RobotFacts | None = None) -> HandPose:
    """One pose: per finger, ``[abd, mcp, pip, dip]`` in degrees (as many as the finger has
    joints), or a table of some of them; each within the ``robot``'s joint range (default:
    the default robot's)."""
    robot = robot_facts(default_robot()) if robot is None else robot
    key = f"poses.{_name(reader, 'poses', name)}"
    table = reader.table(table, key)
    reader.keys(table, key, [], FINGERS)
    angles: dict[int, float] = {}
    for finger, value in table.items():
        fkey, base = f"{key}.{finger}", 4 * FINGERS.index(finger)
        has = [j for j in JOINTS if base + JOINTS.index(j) in robot.hand_ranges]
        if isinstance(value, list):
            joints = dict(zip(has, reader.vector(value, fkey, len(has)), strict=True))
        else:
            sub = reader.table(value, fkey)
            reader.keys(sub, fkey, [], has)
            joints = {j: reader.number(v, f"{fkey}.{j}") for j, v in sub.items()}
        for joint, deg in joints.items():
            bit = base + JOINTS.index(joint)
            problem = hand_problem(joint, math.radians(deg), robot.hand_ranges[bit])
            if problem is not None:
                raise reader.error(f"{fkey}.{joint}", problem)
            angles[bit] = math.radians(deg)
    if not angles:
        raise reader.error(key, f"a pose must set at least one joint of {', '.join(FINGERS)}")
    return HandPose(name, MappingProxyType(dict(sorted(angles.items()))))


def _shared_poses(world: Reader, path: Path, robot: RobotFacts) -> dict[str, HandPose]:
    data = read_toml(path, world)
    reader = Reader(path)
    reader.keys(data, "", ["poses"], [])
    poses = reader.table(data["poses"], "poses")
    return {n: parse_pose(reader, n, t, robot) for n, t in poses.items()}


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


def _program(
    reader: Reader,
    name: str,
    value: Any,
    locations: Mapping[str, Location],
    robot: RobotFacts,
) -> Program:
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
        if isinstance(statement, Drive):
            p = drive_problem(statement.joint, statement.angle, robot.arm_ranges, robot.arm_name)
            if p is not None:
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


def _robot(reader: Reader, value: Any) -> Path:
    """``robot``: a bundled robot's name, or its folder (made absolute by :func:`_load_merged`)."""
    text = reader.string(value, "robot")
    folder = Path(text) if Path(text).is_absolute() else models_dir() / text
    if (folder / ROBOT_FILE).is_file():
        return folder.resolve()
    raise reader.error(
        "robot",
        f"no robot '{text}': neither a folder with a {ROBOT_FILE} nor a bundled robot; "
        f"bundled robots: {', '.join(bundled_robot_names())}",
    )


def _facts(reader: Reader, folder: Path) -> RobotFacts:
    """The robot's facts; a broken robot folder is this world file's problem at ``robot``."""
    try:
        return robot_facts(folder)
    except DialError as e:
        raise reader.error("robot", f"robot {folder.name}: {e}") from None


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
