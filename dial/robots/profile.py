"""Robot profiles: what dial needs to know of a robot, read from its folder's ``robot.toml``.

A robot is a folder: its MJCF, a ``robot.toml`` that names the model's parts dial drives, and a
provenance README. The format, key by key: ``docs/robots.md``. Everything here is pure Python
(no MuJoCo): :func:`read_profile` checks the file's structure and types, every problem at its
key; :mod:`dial.robots.check` then resolves the names against the compiled model.
"""

from __future__ import annotations

import functools
import re
import tomllib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, TypeVar

from dial.errors import Diagnostic, DialError, Span
from dial.resources import data_dir
from dial.robots.fields import Fields, Invalid, Problem
from dial.robots.locate import locate, nearest

FILE = "robot.toml"
DEFAULT_ROBOT = "utah_hand_puma"  # a world file that names no robot runs on this one
LOADS: tuple[str, ...] = ("tendon", "actuator", "joint")
# The fingers, in mask order: the masks have 16 bits, bit 4 f + j for finger f, joint j.
FINGER_NAMES = ("index", "middle", "ring", "thumb")
MAX_JOINTS = 4
MIN_ARM_JOINTS = 6  # a tool position and orientation
Load = Literal["tendon", "actuator", "joint"]
T = TypeVar("T")


@dataclass(frozen=True)
class IKSettings:
    """How the arm's tool-frame IK weighs its tasks; angles in rad."""

    position_cost: float
    orientation_cost: float
    posture_cost: float  # > 0: a posture task towards ``posture`` (a redundant arm's nullspace)
    posture: tuple[float, ...]
    seeds: tuple[tuple[float, ...], ...]  # start offsets tried in order when a solve stalls


@dataclass(frozen=True)
class Arm:
    name: str  # what messages call it: "PUMA joint 3 is beyond its limit"
    joints: tuple[str, ...]  # in order: VAL-II's DRIVE J turns the J-th
    servos: tuple[str, ...]  # their position actuators, same order
    tool_site: str
    home: tuple[float, ...]  # rad: where the IK starts from when nothing else says
    kp: tuple[float, ...]  # servo gains applied to the model (N m/rad, N m s/rad)
    kv: tuple[float, ...]
    ik: IKSettings


@dataclass(frozen=True)
class Finger:
    """One finger: its joints in mask order (abduction, then flexion from the palm out)."""

    name: str
    joints: tuple[str, ...]
    tip_site: str
    tactile: str | None  # a MuJoCo tactile sensor, or None
    servos: tuple[str, ...] = ()  # load "actuator"/"joint": each joint's position actuator
    flexors: tuple[str, ...] = ()  # load "tendon": each joint's flexor actuator
    extensors: tuple[str, ...] = ()


@dataclass(frozen=True)
class HandServo:
    """Gains applied to the hand's actuators: position servos (kp, kv per joint, mask order)
    or a tendon servo (pretension N, stiffness N/rad, damping N s/rad)."""

    kp: tuple[float, ...] = ()
    kv: tuple[float, ...] = ()
    pretension: float = 0.0
    stiffness: float = 0.0
    damping: float = 0.0


@dataclass(frozen=True)
class Hand:
    load: Load  # how joint load is sensed
    lever: float  # m: joint load (N m) over this is the N that scripts' forces are in
    taxels: tuple[int, int]  # rows, columns of every tactile array
    servo: HandServo


@dataclass(frozen=True)
class Limits:
    joint_slack: float  # rad a servo may press an arm joint into its stop before it is a fault
    load: float  # the largest tendon tension (N) or joint torque (N m) a drive exerts
    saturation_time: float  # s: a drive held at ``load`` this long is logged


@dataclass(frozen=True)
class RobotProfile:
    """A robot's ``robot.toml``, its structure checked; paths made absolute."""

    name: str
    description: str
    path: Path  # the robot.toml
    model: Path  # the robot's MJCF (the robot alone)
    worlds: Path  # its world files
    arm: Arm
    fingers: tuple[Finger, ...]
    hand: Hand
    limits: Limits

    @property
    def folder(self) -> Path:
        return self.path.parent

    @property
    def finger_names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.fingers)


@dataclass(frozen=True)
class Parts:
    """What could be read of a robot.toml: a part is None when it is broken (its problems
    recorded), so that names can still be checked in the parts that are sound."""

    path: Path
    top: tuple[str, str, Path, Path] | None  # name, description, model, worlds
    arm: Arm | None
    fingers: tuple[Finger, ...] | None
    hand: Hand | None
    limits: Limits | None

    def profile(self) -> RobotProfile | None:
        """The whole profile, if every part is sound."""
        if not (self.top and self.arm and self.fingers and self.hand and self.limits):
            return None
        name, description, model, worlds = self.top
        return RobotProfile(
            name,
            description,
            self.path,
            model,
            worlds,
            self.arm,
            self.fingers,
            self.hand,
            self.limits,
        )


class RobotFileError(DialError):
    """A ``robot.toml`` with problems; :attr:`diagnostics` holds each one at its place."""

    def __init__(self, diagnostics: list[Diagnostic]) -> None:
        self.diagnostics = diagnostics
        super().__init__("\n".join(d.header for d in diagnostics))

    def __reduce__(self) -> tuple[type[RobotFileError], tuple[list[Diagnostic]]]:
        # Pickled (a worker process's error) as what it was made from, not its message.
        return type(self), (self.diagnostics,)

    def render(self) -> str:
        return "\n".join(d.render() for d in self.diagnostics)


def diagnostics(path: Path, text: str, problems: list[Problem]) -> list[Diagnostic]:
    """Each problem at its line and column of ``text``, with the source line for a caret."""
    places = locate(text)
    lines = text.splitlines()
    out = []
    for problem in problems:
        span = nearest(places, problem.path)
        where = f"{problem.key}: " if problem.path else ""
        source = lines[span.line - 1] if span.line <= len(lines) else ""
        out.append(Diagnostic(str(path), span, where + problem.message, source))
    return sorted(out, key=lambda d: d.span)


def parse_toml(path: Path) -> tuple[str, dict[str, Any]]:
    """The text and data of a robot.toml; a syntax error is a :class:`RobotFileError`."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise DialError(f"{path}: cannot read it: {getattr(e, 'strerror', None) or e}") from None
    try:
        return text, tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        # "... (at line L, column C)": Python 3.11's TOMLDecodeError has no lineno attribute.
        where = re.search(r" \(at line (\d+), column (\d+)\)$", str(e))
        line, col = (int(where[1]), int(where[2])) if where else (1, 1)
        message = f"invalid TOML: {str(e)[: where.start()] if where else e}"
        source = text.splitlines()[line - 1] if 0 < line <= len(text.splitlines()) else ""
        raise RobotFileError([Diagnostic(str(path), Span.at(line, col), message, source)]) from None


def read_profile(folder: Path) -> tuple[Parts, list[Problem], str]:
    """The parts of the folder's robot.toml, every structural problem, and the file's text.

    Raises :class:`RobotFileError` for a TOML syntax error and :class:`DialError` for a
    folder without a robot.toml.
    """
    path = (folder / FILE).resolve()
    if not path.is_file():
        raise DialError(f"{folder}: not a robot folder (no {FILE} in it)")
    text, data = parse_toml(path)
    fields = Fields()
    return _parts(fields, path, data), fields.problems, text


def load_profile(folder: Path) -> RobotProfile:
    """The folder's profile; raises :class:`RobotFileError` listing every structural problem.
    (Its names are resolved against the model by :func:`dial.robots.check.check_robot`.)"""
    parts, problems, text = read_profile(folder)
    profile = parts.profile()
    if problems or profile is None:
        raise RobotFileError(diagnostics(parts.path, text, problems))
    return profile


@functools.cache
def default_profile() -> RobotProfile:
    """The default robot's profile (``models/utah_hand_puma/robot.toml``), read once."""
    return load_profile(data_dir("models") / DEFAULT_ROBOT)


def _parts(f: Fields, path: Path, data: dict[str, Any]) -> Parts:
    required = ["name", "model", "arm", "hand", "fingers", "limits"]
    f.keys(data, (), required, ["description", "worlds"])
    top = _top(f, path, data)
    fingers = _attempt(lambda: _fingers(f, data))
    hand = _attempt(lambda: _hand(f, f.table(data, (), "hand"), fingers))
    if fingers is not None and hand is not None:
        _finger_load(f, fingers, hand.load)
    arm = _attempt(lambda: _arm(f, f.table(data, (), "arm")))
    limits = _attempt(lambda: _limits(f, f.table(data, (), "limits")))
    return Parts(path, top, arm, fingers, hand, limits)


def _attempt(read: Callable[[], T]) -> T | None:
    """A part of the profile, or None if it is broken (its problems recorded): the other
    parts are still read, so that one pass reports every problem."""
    try:
        return read()
    except Invalid:
        return None


def _top(f: Fields, path: Path, data: dict[str, Any]) -> tuple[str, str, Path, Path] | None:
    def read() -> tuple[str, str, Path, Path]:
        name = f.string(data.get("name"), ("name",))
        model = path.parent / f.string(data.get("model"), ("model",))
        worlds = path.parent / f.string(data.get("worlds", "worlds"), ("worlds",))
        description = data.get("description", "")
        if not isinstance(description, str):
            raise f.fail(("description",), "expected a string")
        return name, description, model, worlds

    return _attempt(read)


def _arm(f: Fields, arm: Any) -> Arm:
    p = ("arm",)
    f.keys(arm, p, ["name", "joints", "servos", "tool_site", "home", "kp", "kv"], ["ik"])
    name = f.string(arm.get("name"), (*p, "name"))
    joints = f.names(arm.get("joints"), (*p, "joints"))
    n = len(joints)
    if n < MIN_ARM_JOINTS:
        raise f.fail((*p, "joints"), f"expected at least {MIN_ARM_JOINTS} joints, got {n}")
    servos = f.names(arm.get("servos"), (*p, "servos"), n)
    tool = f.string(arm.get("tool_site"), (*p, "tool_site"))
    home = f.numbers(arm.get("home"), (*p, "home"), n)
    kp = f.per_joint(arm.get("kp"), (*p, "kp"), n)
    kv = f.per_joint(arm.get("kv"), (*p, "kv"), n, zero=True)
    return Arm(name, joints, servos, tool, home, kp, kv, _ik(f, arm.get("ik", {}), home))


def _ik(f: Fields, ik: Any, home: tuple[float, ...]) -> IKSettings:
    p = ("arm", "ik")
    if not isinstance(ik, dict):
        raise f.fail(p, "expected a table")
    optional = ["position_cost", "orientation_cost", "posture_cost", "posture", "seeds"]
    f.keys(ik, p, [], optional)
    n = len(home)
    posture = f.numbers(ik["posture"], (*p, "posture"), n) if "posture" in ik else home
    seeds = tuple(f.numbers(s, (*p, "seeds", i), n) for i, s in enumerate(_list(f, ik, p, "seeds")))
    return IKSettings(
        position_cost=f.number(ik.get("position_cost", 1.0), (*p, "position_cost"), True),
        orientation_cost=f.number(ik.get("orientation_cost", 0.2), (*p, "orientation_cost"), True),
        posture_cost=f.number(ik.get("posture_cost", 0.0), (*p, "posture_cost")),
        posture=posture,
        seeds=((0.0,) * n, *seeds),
    )


def _list(f: Fields, table: Any, path: tuple[str, ...], key: str) -> list[Any]:
    value = table.get(key, [])
    if not isinstance(value, list):
        raise f.fail((*path, key), "expected a list")
    return value


def _hand(f: Fields, hand: Any, fingers: tuple[Finger, ...] | None) -> Hand:
    p = ("hand",)
    tendon = ["pretension", "stiffness", "damping"]
    f.keys(hand, p, ["load", "lever", "taxels"], ["kp", "kv", *tendon])
    load: Load = f.choice(hand.get("load"), (*p, "load"), LOADS)  # type: ignore[assignment]
    lever = f.number(hand.get("lever"), (*p, "lever"), positive=True)
    rows, cols = f.integers(hand.get("taxels"), (*p, "taxels"), 2)
    gains = tendon if load == "tendon" else ["kp", "kv"]
    for key in gains:
        if key not in hand:
            f.problems.append(Problem(p, f"missing key '{key}' (a servo gain of load '{load}')"))
    for key in [k for k in (*tendon, "kp", "kv") if k not in gains]:
        if key in hand:
            f.problems.append(Problem((*p, key), f"not a servo gain of load '{load}'"))
    if load == "tendon":
        values = [f.number(hand.get(k), (*p, k), positive=True) for k in tendon]
        servo = HandServo(pretension=values[0], stiffness=values[1], damping=values[2])
        return Hand(load, lever, (rows, cols), servo)
    n = sum(len(g.joints) for g in fingers or ())
    kp = f.per_joint(hand.get("kp"), (*p, "kp"), n)
    kv = f.per_joint(hand.get("kv"), (*p, "kv"), n, zero=True)
    return Hand(load, lever, (rows, cols), HandServo(kp=kp, kv=kv))


def _fingers(f: Fields, data: dict[str, Any]) -> tuple[Finger, ...]:
    tables = data.get("fingers")
    valid = ", ".join(FINGER_NAMES)
    if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
        raise f.fail(("fingers",), f"expected [[fingers]] tables, one per finger: {valid}")
    if len(tables) != len(FINGER_NAMES):
        where = ("fingers", min(len(tables), len(FINGER_NAMES)))
        raise f.fail(where, f"expected {len(FINGER_NAMES)} fingers, {valid}; got {len(tables)}")
    fingers: list[Finger] = []
    for i, table in enumerate(tables):
        p = ("fingers", i)
        optional = ["tactile", "servos", "flexors", "extensors"]
        f.keys(table, p, ["name", "joints", "tip_site"], optional)
        name = f.string(table.get("name"), (*p, "name"))
        if name != FINGER_NAMES[i]:
            raise f.fail(
                (*p, "name"),
                f"expected '{FINGER_NAMES[i]}' (the fingers are {valid}, in "
                f"this order: finger f holds mask bits 4 f to 4 f + 3), got '{name}'",
            )
        joints = f.names(table.get("joints"), (*p, "joints"))
        if len(joints) > MAX_JOINTS:
            raise f.fail((*p, "joints"), f"at most {MAX_JOINTS} joints a finger (16-bit masks)")
        tactile = f.string(table["tactile"], (*p, "tactile")) if "tactile" in table else None
        lists = {k: f.names(table[k], (*p, k), len(joints)) for k in optional[1:] if k in table}
        tip = f.string(table.get("tip_site"), (*p, "tip_site"))
        fingers.append(Finger(name, joints, tip, tactile, **lists))
    return tuple(fingers)


def _finger_load(f: Fields, fingers: tuple[Finger, ...], load: Load) -> None:
    """Each finger names the actuators its load sensing needs, and no others."""
    need = ("flexors", "extensors") if load == "tendon" else ("servos",)
    for i, finger in enumerate(fingers):
        for key in ("servos", "flexors", "extensors"):
            given = bool(getattr(finger, key))
            if key in need and not given:
                f.problems.append(Problem(("fingers", i), f"missing key '{key}' (load '{load}')"))
            elif key not in need and given:
                f.problems.append(Problem(("fingers", i, key), f"not used with load '{load}'"))


def _limits(f: Fields, limits: Any) -> Limits:
    p = ("limits",)
    f.keys(limits, p, ["joint_slack", "load", "saturation_time"], [])
    return Limits(
        joint_slack=f.number(limits.get("joint_slack"), (*p, "joint_slack"), positive=True),
        load=f.number(limits.get("load"), (*p, "load"), positive=True),
        saturation_time=f.number(limits.get("saturation_time"), (*p, "saturation_time"), True),
    )
