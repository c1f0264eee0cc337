"""The teaching session's commands: their table (usage and help) and a parser of one line.

Parsing is pure: a line becomes a command record or a :class:`CommandError` that says what
was expected. Names (poses, locations, programs, objects) are checked by the session, which
knows the world. Lengths are mm and angles degrees unless a unit is written (``1cm``,
``0.1rad``); VAL-II distances (``appro``, ``depart``) are metres, as in world-file programs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from dial.errors import DialError
from dial.instructions.types import ALL_JOINTS, FINGERS, Finger, ParamError, parse_mask
from dial.scene.valii import NAME, Statement, StatementError, parse_statement
from dial.scene.world import JOINTS
from dial.units import UnitError, parse_quantity

FRAMES = ("world", "tool")
AXES = ("x", "y", "z", "rx", "ry", "rz")
LIMP_S = 0.5  # s a limp command lets the joints settle by default


class CommandError(DialError):
    """A line that is not a valid command; the message lists what is valid."""


@dataclass(frozen=True)
class Jog:
    """Move the tool by ``delta`` (m) and turn it by ``turn`` (rad, rpy) in ``frame``."""

    frame: str
    delta: tuple[float, float, float]
    turn: tuple[float, float, float]


@dataclass(frozen=True)
class Arm:
    """A VAL-II statement: ``move``/``goto``, ``moves``, ``appro``, ``depart``, ``drive``."""

    statement: Statement
    text: str


@dataclass(frozen=True)
class Ex:
    program: str


@dataclass(frozen=True)
class FingerJoints:
    """Finger ``finger``'s joints: ``angles`` (rad) for joints ``joints``, added if relative."""

    finger: int
    joints: tuple[int, ...]
    angles: tuple[float, ...]
    relative: bool


@dataclass(frozen=True)
class Limp:
    mask: int
    seconds: float


@dataclass(frozen=True)
class Pose:
    name: str
    mask: int


@dataclass(frozen=True)
class SavePose:
    name: str
    mask: int
    replace: bool


@dataclass(frozen=True)
class SaveLocation:
    name: str
    obj: str | None
    world_axes: bool
    replace: bool


@dataclass(frozen=True)
class Word:
    """A command without parameters, or with an optional word: undo, where, write, help..."""

    verb: str
    arg: str | None = None


Command = Jog | Arm | Ex | FingerJoints | Limp | Pose | SavePose | SaveLocation | Word


@dataclass(frozen=True)
class Spec:
    usage: str
    summary: str
    parse: Callable[[list[str]], Command]


def _length(text: str) -> float:
    try:
        return parse_quantity(text, "length", "mm")
    except UnitError as e:
        raise CommandError(str(e)) from None


def _angle(text: str) -> float:
    try:
        return parse_quantity(text, "angle", "deg")
    except UnitError as e:
        raise CommandError(str(e)) from None


def _name(text: str, what: str) -> str:
    if not NAME.match(text):
        raise CommandError(f"expected a {what} name ([A-Za-z_][A-Za-z0-9_]*), got '{text}'")
    return text


def _mask(text: str) -> int:
    try:
        return parse_mask(text)
    except ParamError as e:
        raise CommandError(str(e)) from None


def _options(
    words: list[str], keys: tuple[str, ...], flags: tuple[str, ...] = ()
) -> dict[str, str | bool]:
    """Split ``key=value`` words and bare flags off ``words`` (in place)."""
    out: dict[str, str | bool] = {}
    for word in list(words):
        key, eq, value = word.partition("=")
        if eq and key in keys:
            out[key] = value
            words.remove(word)
        elif word in flags:
            out[word] = True
            words.remove(word)
        elif eq:
            valid = ", ".join(f"{k}=" for k in keys) or "none"
            raise CommandError(f"unknown option '{key}='; options: {valid}")
    return out


def _jog(words: list[str]) -> Command:
    frame = words.pop(0) if words and words[0] in FRAMES else "world"
    if len(words) == 2 and words[0] in AXES:
        axis, amount = AXES.index(words[0]), words[1]
        values = [0.0] * 6
        values[axis] = _length(amount) if axis < 3 else _angle(amount)
    elif len(words) in (3, 6):
        values = [_length(w) for w in words[:3]] + [_angle(w) for w in words[3:]]
        values += [0.0] * (6 - len(values))
    else:
        raise CommandError(f"usage: {SPECS['jog'].usage}")
    return Jog(frame, (values[0], values[1], values[2]), (values[3], values[4], values[5]))


def _valii(verb: str) -> Callable[[list[str]], Command]:
    def parse(words: list[str]) -> Command:
        text = " ".join(["MOVE" if verb == "goto" else verb.upper(), *words])
        try:
            statement = parse_statement(text)
        except StatementError as e:
            raise CommandError(f"{e} (usage: {SPECS[verb].usage})") from None
        if statement is None:
            raise CommandError(f"usage: {SPECS[verb].usage}")
        return Arm(statement, " ".join([verb, *words]))

    return parse


def _ex(words: list[str]) -> Command:
    if len(words) != 1:
        raise CommandError(f"usage: {SPECS['ex'].usage}")
    return Ex(_name(words[0], "program"))


def _finger(words: list[str]) -> Command:
    if len(words) not in (3, 5):
        raise CommandError(f"usage: {SPECS['finger'].usage}")
    try:
        finger = Finger().parse(words[0])
    except ParamError as e:
        raise CommandError(str(e)) from None
    if len(words) == 5:
        return FingerJoints(finger, (0, 1, 2, 3), tuple(_angle(w) for w in words[1:]), False)
    if words[1] not in JOINTS:
        raise CommandError(f"unknown joint '{words[1]}'; joints: {', '.join(JOINTS)}")
    return FingerJoints(finger, (JOINTS.index(words[1]),), (_angle(words[2]),), True)


def _fingers_mask(words: list[str], given: object) -> int:
    """A joint mask from finger names and an optional ``fingers=MASK``; all joints if neither."""
    mask = _mask(str(given)) if given is not None else 0
    for word in words:
        if word not in FINGERS:
            raise CommandError(f"unknown finger '{word}'; fingers: {', '.join(FINGERS)}")
        mask |= 0xF << (4 * FINGERS.index(word))
    return mask or ALL_JOINTS


def _limp(words: list[str]) -> Command:
    opts = _options(words, ("fingers", "for"))
    seconds = LIMP_S
    if "for" in opts:
        try:
            seconds = parse_quantity(str(opts["for"]), "time", "s")
        except UnitError as e:
            raise CommandError(str(e)) from None
        if not 0.0 < seconds <= 10.0:
            raise CommandError(f"for= must be from 0 to 10 s, got {opts['for']}")
    return Limp(_fingers_mask(words, opts.get("fingers")), seconds)


def _pose(words: list[str]) -> Command:
    opts = _options(words, ("fingers",))
    if len(words) != 1:
        raise CommandError(f"usage: {SPECS['pose'].usage}")
    return Pose(_name(words[0], "pose"), _fingers_mask([], opts.get("fingers")))


def _save(words: list[str]) -> Command:
    if not words or words[0] not in ("pose", "location"):
        raise CommandError(f"usage: {SPECS['save'].usage}")
    kind, rest = words[0], words[1:]
    opts = _options(rest, ("fingers", "axes") if kind == "location" else ("fingers",), ("replace",))
    replace = bool(opts.get("replace"))
    if kind == "pose":
        if len(rest) != 1:
            raise CommandError("usage: save pose NAME [fingers=MASK] [replace]")
        return SavePose(_name(rest[0], "pose"), _fingers_mask([], opts.get("fingers")), replace)
    usage = "save location NAME [relative-to OBJECT [axes=world]] [replace]"
    if len(rest) == 1:
        obj = None
    elif len(rest) == 3 and rest[1] == "relative-to":
        obj = rest[2]
    else:
        raise CommandError(f"usage: {usage}")
    axes = str(opts.get("axes", "object"))
    if axes not in ("object", "world"):
        raise CommandError(f"axes= must be object or world, got '{axes}'")
    if axes == "world" and obj is None:
        raise CommandError("axes=world applies to a location relative-to an object")
    return SaveLocation(_name(rest[0], "location"), obj, axes == "world", replace)


def _word(verb: str, arg: bool = False) -> Callable[[list[str]], Command]:
    def parse(words: list[str]) -> Command:
        if len(words) > (1 if arg else 0):
            raise CommandError(f"usage: {SPECS[verb].usage}")
        return Word(verb, words[0] if words else None)

    return parse


SPECS: dict[str, Spec] = {
    "jog": Spec(
        "jog [world|tool] DX DY DZ [RX RY RZ]  |  jog [world|tool] x|y|z|rx|ry|rz AMOUNT",
        "move the tool in a straight line (mm) and turn it (deg), in the world or tool frame",
        _jog,
    ),
    "drive": Spec("drive J DEG", "turn arm joint J by DEG degrees", _valii("drive")),
    "finger": Spec(
        "finger F JOINT DEG  |  finger F ABD MCP PIP DIP",
        "turn one joint (abd, mcp, pip, dip) of finger F by DEG, or set all four (deg)",
        _finger,
    ),
    "limp": Spec(
        "limp [FINGER...] [fingers=MASK] [for=S]",
        f"make joints back-drivable for S s (default {LIMP_S:g}), then hold where they rest",
        _limp,
    ),
    "goto": Spec("goto LOCATION", "move to a location (joint-interpolated)", _valii("goto")),
    "move": Spec("move LOCATION", "VAL-II MOVE: the same as goto", _valii("move")),
    "moves": Spec("moves LOCATION", "VAL-II MOVES: a straight line to a location", _valii("moves")),
    "appro": Spec(
        "appro LOCATION D", "VAL-II APPRO: D (m, or 50mm) back from a location", _valii("appro")
    ),
    "depart": Spec("depart D", "VAL-II DEPART: D (m) back along the tool z axis", _valii("depart")),
    "ex": Spec("ex PROGRAM", "run a stored arm program of the world file", _ex),
    "pose": Spec("pose NAME [fingers=MASK]", "apply a hand pose (only the masked joints)", _pose),
    "save": Spec(
        "save pose NAME [fingers=MASK] [replace]  |  "
        "save location NAME [relative-to OBJECT [axes=world]] [replace]",
        "name the hand's joint angles, or the tool pose (in the world or an object's frame)",
        _save,
    ),
    "undo": Spec("undo", "go back to before the last command that moved or saved", _word("undo")),
    "where": Spec("where", "tool pose, joint angles and contacts", _word("where")),
    "names": Spec("names", "the scene's objects, poses, locations and programs", _word("names")),
    "write": Spec("write", "write the saved names into the world file", _word("write")),
    "help": Spec("help [COMMAND]", "the commands, or one command's usage", _word("help", True)),
    "quit": Spec("quit", "end (asks first if saved names are not written)", _word("quit")),
    "quit!": Spec("quit!", "end, dropping saved names that are not written", _word("quit!")),
}


def strip_comment(line: str) -> str:
    """The line without a ``#`` comment (for commented session scripts)."""
    return line.split("#", 1)[0].strip()


def parse_command(line: str) -> Command | None:
    """One command from a line; None for a blank or comment-only line."""
    words = strip_comment(line).split()
    if not words:
        return None
    verb = words[0]
    spec = SPECS.get(verb)
    if spec is None:
        raise CommandError(f"unknown command '{verb}'; commands: {', '.join(SPECS)}")
    return spec.parse(words[1:])


def help_text(verb: str | None = None) -> str:
    """The command table, or one command's usage and summary."""
    if verb is not None:
        if verb not in SPECS:
            raise CommandError(f"unknown command '{verb}'; commands: {', '.join(SPECS)}")
        return f"{SPECS[verb].usage}\n  {SPECS[verb].summary}"
    lines = [f"  {s.usage}\n      {s.summary}" for s in SPECS.values()]
    return "commands:\n" + "\n".join(lines)
