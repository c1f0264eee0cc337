"""What an event asks of the robot its scene binds it to, checked before anything runs.

A script is written against the paper's hand; the robot a world file names may have less:
no tactile array on a finger, fewer joints (mask bits that are no joint), fewer or other arm
joints. Each problem names the robot and the parameter it is about, so that the checker can
point at it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

from dial.instructions.limits import drive_problem
from dial.instructions.types import FINGERS
from dial.robots.facts import RobotFacts, default_facts

if TYPE_CHECKING:
    from dial.errors import Span
    from dial.parser.ast import Definition
    from dial.parser.bind import Bound

Problem = tuple[str | None, str]  # the parameter it is about (None: the instruction), message


def robot_errors(d: Definition, bound: Bound, robot: RobotFacts | None) -> list[tuple[Span, str]]:
    """Each problem of one bound event on ``robot`` (the default robot when None), at the
    parameter it is about (else the instruction)."""
    problems = robot_problems(d.instruction, bound.args, robot or default_facts())
    return [
        (bound.spans.get(param, d.instruction_span) if param else d.instruction_span, message)
        for param, message in problems
    ]


def robot_problems(
    instruction: str, args: Mapping[str, object], robot: RobotFacts
) -> list[Problem]:
    """Every problem of one event's arguments on ``robot``."""
    out: list[Problem] = []
    for name in ("fingers", "masks"):
        value = args.get(name)
        masks = value if isinstance(value, tuple) else (value,)
        for mask in masks:
            if isinstance(mask, int):
                out += _mask(name, mask, robot)
    out += _tactile(instruction, args, robot)
    if instruction == "puma_command" and args.get("verb") == "drive":
        out += _drive(args.get("joint"), args.get("angle"), robot)
    return out


def _drive(joint: object, angle: object, robot: RobotFacts) -> list[Problem]:
    if not isinstance(joint, int) or not isinstance(angle, float):
        return []  # a bad number: the binder reports it
    if not 1 <= joint <= len(robot.arm_ranges):
        arm = f"the {robot.arm_name} has joints 1 to {len(robot.arm_ranges)}"
        return [("joint", f"robot '{robot.name}': {arm}, not {joint}")]
    problem = drive_problem(joint, angle, robot.arm_ranges, robot.arm_name)
    return [] if problem is None else [(None, problem)]


def _mask(name: str, mask: int, robot: RobotFacts) -> list[Problem]:
    lacks = robot.lacks(mask)
    if not lacks:
        return []
    joints = ", ".join(robot.joint_name(bit) for bit in lacks)
    return [
        (
            name,
            f"robot '{robot.name}' has no {joints} joint (mask bit{'s' if len(lacks) > 1 else ''} "
            f"{', '.join(str(b) for b in lacks)}); its joints are mask 0x{robot.mask:04X}",
        )
    ]


def _tactile(instruction: str, args: Mapping[str, object], robot: RobotFacts) -> list[Problem]:
    """A tactile reading asked of a finger without an array."""
    fingers: tuple[object, ...]
    if instruction in ("tactile_contact", "record_contact"):
        if args.get("source", "tactile") != "tactile":
            return []
        finger = args.get("finger")
        fingers = (finger,) if isinstance(finger, int) else ()
        where = "finger"
    elif instruction == "guarded_move":
        until = args.get("until")
        if not isinstance(until, tuple) or not any(kind == "tactile" for kind, _ in until):
            return []
        sense = args.get("sense", args.get("finger"))
        where = "sense" if isinstance(args.get("sense"), int) else "until"
        # All fingers sensing: one array among them is enough.
        fingers = (sense,) if isinstance(sense, int) else () if robot.tactile else (0,)
    else:
        return []
    missing = [f for f in fingers if isinstance(f, int) and f not in robot.tactile]
    if not missing:
        return []
    have = ", ".join(FINGERS[f] for f in sorted(robot.tactile)) or "none"
    names = " or ".join(FINGERS[f] for f in missing)
    return [
        (
            where,
            f"robot '{robot.name}' has no tactile array on the {names} (fingers with one: {have})",
        )
    ]
