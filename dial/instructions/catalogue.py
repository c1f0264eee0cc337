"""The instruction set (DESIGN 3) as pure-Python declarations.

Each :class:`Instruction` says which effectors an event uses (as a function of
its parameters), whether its length is zero, fixed or indeterminate, and the
schema of its parameters. The checker binds definitions against it; the
primitives implement it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Literal

from dial.instructions.limits import drive_problem
from dial.instructions.scene_names import SceneNames
from dial.instructions.types import (
    ALL_JOINTS,
    ARM,
    FINGERS,
    Choice,
    Conditions,
    Contact,
    ContactKind,
    Finger,
    Integer,
    Mask,
    MaskPair,
    Name,
    Names,
    ParamType,
    Quantity,
    mask_fingers,
)

Length = Literal["zero", "fixed", "indeterminate"]
Args = Mapping[str, object]
EffectorFn = Callable[[Args, "SceneNames | None"], frozenset[str]]

# Largest tension a tendon actuator can pull (N); grasp thresholds must stay below it.
TENDON_TENSION_LIMIT = 50.0
DEFAULT_TIMEOUT = 10.0
REQUIRED = object()


@dataclass(frozen=True)
class ParamSpec:
    """One parameter: its name, type, default (``REQUIRED`` if none) and role."""

    name: str
    type: ParamType
    default: object = REQUIRED
    positional: bool = False
    doc: str = ""

    @property
    def required(self) -> bool:
        return self.default is REQUIRED


@dataclass(frozen=True)
class Instruction:
    """A primitive the scripts can bind events to."""

    name: str
    length: Length
    params: tuple[ParamSpec, ...]
    effectors: EffectorFn
    usage: str
    summary: str
    # Instructions with no effector ever; only these may be condition-only events.
    sensing: bool = False
    # A custom binder for verb-style parameter lists (puma_command).
    verbs: Mapping[str, tuple[ParamSpec, ...]] = field(default_factory=dict)
    # Allowed numbers of positional words, when optional ones come in groups (arm_move).
    positional_counts: tuple[int, ...] = ()
    # Cross-parameter rule: returns a message when the bound arguments do not fit together.
    validate: Callable[[Args], str | None] | None = None
    # The class that runs it (dial.primitives names each class by this name).
    primitive: str = ""
    # For the contact instructions: the contact kind (tactile, force, position) their
    # condition reads; only these can be watched with '~' (DESIGN 2.7).
    condition: ContactKind | None = None

    def spec(self, name: str) -> ParamSpec | None:
        return next((p for p in self.params if p.name == name), None)


def _none(args: Args, scene: SceneNames | None) -> frozenset[str]:
    return frozenset()


def _arm(args: Args, scene: SceneNames | None) -> frozenset[str]:
    return frozenset({ARM})


def _finger(args: Args, scene: SceneNames | None) -> frozenset[str]:
    finger = args["finger"]
    assert isinstance(finger, int)
    return frozenset({FINGERS[finger]})


def _fingers_mask(args: Args, scene: SceneNames | None) -> frozenset[str]:
    mask = args["fingers"]
    assert isinstance(mask, int)
    return mask_fingers(mask)


def _hand_pose(args: Args, scene: SceneNames | None) -> frozenset[str]:
    mask = args.get("fingers")
    if mask is None:
        pose = args["pose"]
        known = scene.poses.get(str(pose)) if scene is not None else None
        mask = known if known is not None else ALL_JOINTS
    assert isinstance(mask, int)
    return mask_fingers(mask)


def _grasp(args: Args, scene: SceneNames | None) -> frozenset[str]:
    masks = args["masks"]
    assert isinstance(masks, tuple)
    return mask_fingers(masks[0])


def _guarded(args: Args, scene: SceneNames | None) -> frozenset[str]:
    return _arm(args, scene) if args.get("finger") is None else _finger(args, scene)


def _check_puma(args: Args) -> str | None:
    if args.get("verb") != "drive":
        return None
    joint, angle = args["joint"], args["angle"]
    assert isinstance(joint, int) and isinstance(angle, float)
    return drive_problem(joint, angle)


def _check_guarded(args: Args) -> str | None:
    if all(args[k] == 0.0 for k in ("dx", "dy", "dz")):
        return "guarded_move needs a nonzero direction DX DY DZ"
    frame = args.get("frame")
    if args.get("finger") is None and frame == "palm":
        return "frame=palm is for finger moves; an arm guarded_move takes frame=tool or world"
    if args.get("finger") is not None and frame == "tool":
        return "frame=tool is for arm moves; a finger guarded_move takes frame=palm or world"
    return None


_LEN = Quantity("length", "m", -1.0, 1.0)
_ROT = Quantity("angle", "rad", -6.2832, 6.2832)
_TIMEOUT = ParamSpec(
    "timeout",
    Quantity("time", "s", 0.0, 3600.0, lo_open=True),
    DEFAULT_TIMEOUT,
    doc="give up (outcome timeout) after this much simulated time",
)
_FINGER = ParamSpec("finger", Finger(), doc="which finger")
_XYZ = tuple(
    ParamSpec(n, _LEN, positional=True, doc=f"{n[-1]} displacement") for n in ("dx", "dy", "dz")
)


def _sensing(name: str, summary: str) -> Instruction:
    return Instruction(name, "zero", (), _none, name, summary, sensing=True, primitive="Get")


def _contact(
    kind: ContactKind, dim_unit: tuple[str, str], default: float, what: str
) -> Instruction:
    name = f"{kind}_contact"
    dim, unit = dim_unit
    threshold = Quantity(dim, unit, 0.0, 1000.0, lo_open=True)  # type: ignore[arg-type]
    return Instruction(
        name,
        "indeterminate",
        (_FINGER, ParamSpec("threshold", threshold, default, doc=what), _TIMEOUT),
        _none,
        f"{name} finger=F [threshold=X{unit}] [timeout=S]",
        f"Wait until {what} on the finger passes the threshold.",
        sensing=True,
        primitive="ContactWait",
        condition=kind,
    )


_PUMA_VERBS: dict[str, tuple[ParamSpec, ...]] = {
    "ex": (ParamSpec("program", Name("program"), doc="stored program in the world file"),),
    "move": (ParamSpec("location", Name("location"), doc="joint-interpolated move"),),
    "moves": (ParamSpec("location", Name("location"), doc="straight-line move"),),
    "appro": (
        ParamSpec("location", Name("location")),
        ParamSpec("distance", Quantity("length", "m", 0.0, 1.0), doc="back along tool z"),
    ),
    "depart": (ParamSpec("distance", Quantity("length", "m", -1.0, 1.0), doc="back along tool z"),),
    "drive": (
        ParamSpec("joint", Integer(1, 6)),
        ParamSpec(
            "angle", Quantity("angle", "deg", -6.2832, 6.2832), doc="degrees unless suffixed"
        ),
    ),
}

INSTRUCTIONS: dict[str, Instruction] = {
    i.name: i
    for i in (
        _sensing("get_joints", "Record the 16 hand joint angles."),
        _sensing("get_forces", "Record the 32 tendon tensions."),
        _sensing("get_tactile", "Record the 4x16x16 fingertip taxels."),
        _sensing("get_wrist", "Record the wrist (tool) pose."),
        Instruction(
            "hand_pose",
            "fixed",
            (
                ParamSpec("pose", Name("pose"), positional=True, doc="named hand pose"),
                ParamSpec("fingers", Mask(), None, doc="only these joints (default: the pose's)"),
            ),
            _hand_pose,
            'hand_pose "NAME" [fingers=MASK]',
            "Move the hand to a named pose (GOTO MOVE or TRAJECTORY MOVE).",
            primitive="HandPose",
        ),
        Instruction(
            "finger_move",
            "fixed",
            (_FINGER, *_XYZ, ParamSpec("frame", Choice(("palm", "world")), "palm")),
            _finger,
            "finger_move finger=F DX DY DZ [frame=palm|world]",
            "Move a fingertip along a straight line by IK on the finger's joints.",
            primitive="FingerMove",
        ),
        Instruction(
            "puma_command",
            "fixed",
            (ParamSpec("verb", Choice(tuple(_PUMA_VERBS)), positional=True),),
            _arm,
            'puma_command "ex PROG" | "move LOC" | "moves LOC" | "appro LOC D" | "depart D" '
            '| "drive J DEG"',
            "Run a VAL-II command or stored program, time-scaled to the run's span.",
            verbs=_PUMA_VERBS,
            validate=_check_puma,
            primitive="PumaCommand",
        ),
        Instruction(
            "arm_move",
            "fixed",
            (
                *_XYZ,
                *(
                    ParamSpec(n, _ROT, 0.0, positional=True, doc="rotation")
                    for n in ("rx", "ry", "rz")
                ),
                ParamSpec("frame", Choice(("tool", "world")), "tool"),
            ),
            _arm,
            "arm_move DX DY DZ [RX RY RZ] [frame=tool|world]",
            "Relative straight-line Cartesian move of the tool.",
            positional_counts=(3, 6),
            primitive="ArmMove",
        ),
        _contact("position", ("length", "mm"), 0.003, "the fingertip position error"),
        _contact("force", ("force", "N"), 0.5, "the change in tendon force differential"),
        _contact("tactile", ("length", "mm"), 0.0001, "the deepest taxel reading"),
        Instruction(
            "grasp_force",
            "indeterminate",
            (
                ParamSpec(
                    "masks", MaskPair(), positional=True, doc="joints to close, tendons to watch"
                ),
                ParamSpec(
                    "force",
                    Quantity("force", "N", 0.0, TENDON_TENSION_LIMIT, lo_open=True),
                    positional=True,
                    doc="flexor-minus-extensor tension that stops a joint",
                ),
                ParamSpec(
                    "speed",
                    Quantity("angular_speed", "rad/s", 0.0, 10.0, lo_open=True),
                    0.8,
                    doc="closing speed of each joint",
                ),
                _TIMEOUT,
            ),
            _grasp,
            'grasp_force "JMASK_TMASK FORCE" [speed=RAD/S] [timeout=S]',
            "Close masked joints until each tendon-masked joint feels FORCE (GRASP WITH FORCE).",
            primitive="GraspForce",
        ),
        Instruction(
            "guarded_move",
            "indeterminate",
            (
                ParamSpec("finger", Finger(), None, doc="move this fingertip (default: the arm)"),
                *_XYZ,
                ParamSpec("until", Conditions(), doc="contact conditions that stop the move"),
                ParamSpec("sense", Finger(), None, doc="finger whose sensors are watched"),
                ParamSpec("max", Quantity("length", "m", 0.0, 1.0, lo_open=True), None),
                ParamSpec(
                    "press",
                    Quantity("length", "m", 0.0, 0.01),
                    0.0,
                    doc="after contact, set the effector this much further on, to keep touching",
                ),
                ParamSpec("frame", Choice(("tool", "palm", "world")), None),
                ParamSpec("speed", Quantity("speed", "m/s", 0.0, 1.0, lo_open=True), 0.05),
                _TIMEOUT,
            ),
            _guarded,
            "guarded_move [finger=F] DX DY DZ until=KIND[:THRESHOLD],... [sense=F] [max=D] "
            "[press=D] [frame=tool|palm|world] [speed=V] [timeout=S]",
            "Move along a direction until contact is sensed, checked at every physics step.",
            validate=_check_guarded,
            primitive="GuardedMove",
        ),
        Instruction(
            "limp",
            "fixed",
            (
                ParamSpec("fingers", Mask(), ALL_JOINTS, doc="joints to make back-drivable"),
                ParamSpec("save", Name("pose"), None, doc="save the reached pose under this name"),
            ),
            _fingers_mask,
            "limp [fingers=MASK] [save=NAME]",
            "Make joints back-drivable; record the reached pose at the end (teaching).",
            primitive="Limp",
        ),
        Instruction(
            "record_contact",
            "zero",
            (
                _FINGER,
                ParamSpec("into", Name("set"), "contacts", doc="point set to append to"),
                ParamSpec(
                    "at",
                    Choice(("now", "stop")),
                    "now",
                    doc="now, or where the latest guarded move sensing the finger stopped",
                ),
                ParamSpec(
                    "source",
                    Choice(("tactile", "links")),
                    "tactile",
                    doc="the taxel centroid, or the contact point of the finger's links",
                ),
            ),
            _none,
            "record_contact finger=F [into=SET] [at=now|stop] [source=tactile|links]",
            "Append where the finger touches (world frame) to a point set.",
            sensing=True,
            primitive="RecordContact",
        ),
        Instruction(
            "locate",
            "zero",
            (
                ParamSpec(
                    "location",
                    Name("location", anchored=True),
                    positional=True,
                    doc="where the tool is now, relative to the object found",
                ),
                ParamSpec("also", Names("object"), (), doc="objects that moved with it"),
            ),
            _none,
            'locate "LOCATION" [also=OBJECT,...]',
            "The tool is at LOCATION of its object: shift the object's believed position there.",
            sensing=True,
            primitive="Locate",
        ),
        Instruction(
            "fit_plane",
            "zero",
            (ParamSpec("set", Name("set"), "contacts", positional=True),),
            _none,
            "fit_plane [SET]",
            "Least-squares plane through a point set: normal, residual, extents.",
            sensing=True,
            primitive="Fit",
        ),
        Instruction(
            "fit_superquadric",
            "zero",
            (ParamSpec("set", Name("set"), "contacts", positional=True),),
            _none,
            "fit_superquadric [SET]",
            "Least-squares superquadric through a point set: size, shape exponents, pose.",
            sensing=True,
            primitive="Fit",
        ),
    )
}


def contact_condition(instruction: Instruction, args: Args) -> Contact:
    """A contact instruction's condition: it holds when the finger's ``kind`` reading
    reaches the threshold (m or N)."""
    if instruction.condition is None:
        raise ValueError(f"{instruction.name} has no contact condition")
    finger, threshold = args["finger"], args["threshold"]
    assert isinstance(finger, int) and isinstance(threshold, float)
    return Contact(instruction.condition, finger, threshold)
