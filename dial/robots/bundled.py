"""The bundled robots, and what ``dial robots`` says of each (pure Python, no MuJoCo)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from dial.robots.profile import RobotProfile, load_profile
from dial.scene.resolve import bundled_name, bundled_robot_names, models_dir

_LOAD_TEXT = {
    "tendon": "tendon tensions (a flexor and an extensor per joint, N)",
    "actuator": "actuator forces (N m)",
    "joint": "joint torques (N m)",
}


def bundled_robots() -> tuple[Path, ...]:
    """The bundled robot folders: the default robot first, then by name."""
    return tuple(models_dir() / name for name in bundled_robot_names())


def scenes(profile: RobotProfile) -> tuple[str, ...]:
    """The robot's scenes: bundled names (as ``@scene`` takes them) or world file names."""
    names = (bundled_name(p) or p.stem for p in profile.worlds.glob("*.toml"))
    return tuple(sorted(n for n in names if n != "hand_poses"))


def describe(profile: RobotProfile) -> dict[str, Any]:
    """The robot as ``dial robots --json`` reports it."""
    return {
        "name": profile.name,
        "folder": str(profile.folder),
        "description": profile.description,
        "model": profile.model.name,
        "arm": {"joints": list(profile.arm.joints), "tool_site": profile.arm.tool_site},
        "fingers": [
            {
                "name": f.name,
                "joints": list(f.joints),
                "tip_site": f.tip_site,
                "tactile": f.tactile,
            }
            for f in profile.fingers
        ],
        "sensors": {
            "load": profile.hand.load,
            "lever": profile.hand.lever,
            "tactile": [f.name for f in profile.fingers if f.tactile is not None],
            "taxels": list(profile.hand.taxels),
        },
        "scenes": list(scenes(profile)),
    }


def listing(profiles: list[RobotProfile]) -> str:
    """``dial robots``: each robot as a short block of aligned text."""
    blocks = []
    for p in profiles:
        fingers = ", ".join(f"{f.name} {len(f.joints)}" for f in p.fingers)
        hand = sum(len(f.joints) for f in p.fingers)
        tactile = [f.name for f in p.fingers if f.tactile is not None]
        rows, cols = p.hand.taxels
        touch = f"{rows}x{cols} tactile on {', '.join(tactile)}" if tactile else "no tactile"
        lines = [
            f"{p.name}  ({p.folder})",
            f"  {p.description}" if p.description else "",
            f"  arm      {len(p.arm.joints)} joints ({p.arm.joints[0]} .. "
            f"{p.arm.joints[-1]}), tool site {p.arm.tool_site}",
            f"  fingers  {fingers} joints ({hand} in all)",
            f"  sensors  load: {_LOAD_TEXT[p.hand.load]}; {touch}",
            f"  scenes   {', '.join(scenes(p)) or '(none)'}",
        ]
        blocks.append("\n".join(line for line in lines if line))
    return "\n\n".join(blocks) + "\n"


def bundled_profiles() -> list[RobotProfile]:
    return [load_profile(folder) for folder in bundled_robots()]
