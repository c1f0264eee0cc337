"""``dial world S``: a scene's names as aligned text (a pure function of the world model).

Objects with their believed poses (where the world model has them at load), hand poses,
locations (in the world, and as defined when relative to an object), programs and success
criteria. Lengths are printed in mm and angles in degrees, as a user jogs and writes them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import fields

from dial.geometry import location_pose
from dial.instructions.types import FINGERS
from dial.robot.snapshot import FloatArray
from dial.scene.criteria import Criterion
from dial.scene.valii import Appro, Depart, Drive, Move, Statement
from dial.scene.world import JOINTS, HandPose, World
from dial.teach.frames import deg_text, matrix_rpy, mm_text

Believed = Mapping[str, tuple[FloatArray, FloatArray]]


def columns(rows: list[list[str]], indent: str = "  ") -> list[str]:
    """Rows of cells, each column padded to its widest cell (the last one is not padded)."""
    if not rows:
        return [f"{indent}(none)"]
    widths = [max(len(r[i]) for r in rows if i < len(r)) for i in range(max(map(len, rows)))]
    out = []
    for row in rows:
        cells = [c.ljust(widths[i]) for i, c in enumerate(row[:-1])] + [row[-1]]
        out.append((indent + "  ".join(cells)).rstrip())
    return out


def pose_text(pose: HandPose) -> str:
    """``index [0, 5, 5, 5]  middle {abd 15}``: a pose's joints in degrees, per finger."""
    parts = []
    for f, finger in enumerate(FINGERS):
        joints = [(j, pose.angles[4 * f + j]) for j in range(4) if 4 * f + j in pose.angles]
        if len(joints) == 4:
            parts.append(f"{finger} [{', '.join(f'{math.degrees(a):g}' for _, a in joints)}]")
        elif joints:
            inner = ", ".join(f"{JOINTS[j]} {math.degrees(a):g}" for j, a in joints)
            parts.append(f"{finger} {{{inner}}}")
    return "  ".join(parts)


def statement_text(st: Statement) -> str:
    """A program statement as VAL-II text (distances in mm, angles in degrees)."""
    if isinstance(st, Move):
        return f"{'MOVES' if st.straight else 'MOVE'} {st.location}"
    if isinstance(st, Appro):
        return f"APPRO {st.location} {st.distance * 1000:g}mm"
    if isinstance(st, Depart):
        return f"DEPART {st.distance * 1000:g}mm"
    assert isinstance(st, Drive)
    return f"DRIVE {st.joint} {math.degrees(st.angle):g}"


def criterion_text(criterion: Criterion) -> str:
    """``key=value`` pairs as the world file writes them (``_deg`` keys in degrees)."""
    parts = []
    for f in fields(criterion):
        if f.name == "name":
            continue
        key = f.metadata.get("key", f.name)
        value = getattr(criterion, f.name)
        if key.endswith("_deg"):
            value = f"{math.degrees(value):g}"
        elif isinstance(value, tuple):
            value = ",".join(value)
        elif isinstance(value, float):
            value = f"{value:g}"
        parts.append(f"{key}={value}")
    return " ".join(parts)


def describe(
    world: World, believed: Believed, sizes: Mapping[str, FloatArray] | None = None
) -> str:
    """Every name of ``world``; ``believed`` maps each object's body to its pose at load, and
    ``sizes`` to its believed half-sizes where known (a world file saved by ``dial run
    --save-world``)."""
    lines = [f"scene {world.name}: {world.path}", f"model {world.model_path.name}"]
    if world.thread_turns is not None:
        lines.append(f"thread {world.thread_turns:g} turns until it lets go")
    lines.append("")
    sized = {b: v for b, v in (sizes or {}).items() if b in world.objects.values()}
    size_note = "; size: half-sizes mm" if sized else ""
    lines.append(f"objects (believed pose at load: pos mm, rpy deg{size_note})")
    rows = []
    for alias, body in world.objects.items():
        pos, rot = believed[body]
        row = [alias, body, f"pos {mm_text(pos)}", f"rpy {deg_text(matrix_rpy(rot))}"]
        if body in sized:
            row.append(f"size {mm_text(sized[body])}")
        rows.append(row)
    lines += columns(rows)
    lines += ["", "poses (deg: [abd, mcp, pip, dip], or the joints set)"]
    lines += columns([[n, f"0x{p.mask:04X}", pose_text(p)] for n, p in sorted(world.poses.items())])
    lines += ["", "locations (tool frame: pos mm, rpy deg; in the world, then as defined)"]
    rows = []
    for name, loc in world.locations.items():
        pos, rot = location_pose(world, dict(believed), name)
        defined = "absolute"
        if loc.body is not None:
            alias = next(a for a, b in world.objects.items() if b == loc.body)
            axes = ", world axes" if loc.axes == "world" else ""
            rpy = [math.degrees(a) for a in loc.rpy]
            defined = f"relative to {alias}{axes}: pos {mm_text(loc.pos)} rpy {deg_text(rpy)}"
        rows.append([name, f"pos {mm_text(pos)}", f"rpy {deg_text(matrix_rpy(rot))}", defined])
    lines += columns(rows)
    lines += ["", "programs"]
    lines += columns(
        [[n, "; ".join(statement_text(s) for s in p.statements)] for n, p in world.programs.items()]
    )
    lines += ["", "success criteria"]
    lines += columns([[c.name, c.kind, criterion_text(c)] for c in world.criteria])
    return "\n".join(lines) + "\n"
