"""The bundled robots, and what ``dial robots`` says of each (pure Python, no MuJoCo)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from dial.errors import DialError
from dial.resources import data_dir
from dial.robots.profile import FILE, RobotProfile, load_profile

DEFAULT = "utah_hand_puma"  # the robot of a world file that names none
POSES_FILE = "hand_poses.toml"  # shared hand poses beside the world files, not a scene

_LOAD_TEXT = {
    "tendon": "tendon tensions (a flexor and an extensor per joint, N)",
    "actuator": "actuator forces (N m)",
    "joint": "joint torques (N m)",
}


def bundled_robots() -> tuple[Path, ...]:
    """The bundled robot folders: the default robot first, then by name."""
    folders = sorted(p.parent for p in data_dir("models").glob(f"*/{FILE}"))
    return tuple(sorted(folders, key=lambda p: (p.name != DEFAULT, p.name)))


def robot_folder(name: str, base: Path | None = None) -> Path:
    """A robot by bundled name, or a folder (relative to ``base``) holding a robot.toml."""
    path = Path(name).expanduser()
    if not path.is_absolute() and base is not None:
        path = base / path
    if (path / FILE).is_file():
        return path.resolve()
    bundled = {p.name: p for p in bundled_robots()}
    if name in bundled:
        return bundled[name]
    raise DialError(
        f"unknown robot '{name}': neither a folder with a {FILE} nor a bundled robot; "
        f"bundled robots: {', '.join(bundled)}"
    )


def scenes(profile: RobotProfile) -> tuple[str, ...]:
    """The robot's world files, by name."""
    return tuple(sorted(p.stem for p in profile.worlds.glob("*.toml") if p.name != POSES_FILE))


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
