"""``dial robots check DIR``: a robot folder against its MJCF, every problem at its TOML line."""

from __future__ import annotations

from pathlib import Path

import mujoco

from dial.errors import Diagnostic, DialError
from dial.robots.fields import Problem
from dial.robots.profile import Parts, RobotFileError, diagnostics, read_profile
from dial.robots.resolve import resolve


def check_robot(folder: Path) -> list[Diagnostic]:
    """Every problem of the folder's ``robot.toml``: its syntax, its structure, and then its
    names and figures against the compiled model. Empty when the robot is fine.

    Raises :class:`DialError` for a folder without a ``robot.toml``.
    """
    try:
        parts, problems, text = read_profile(folder)
    except RobotFileError as e:
        return e.diagnostics
    if parts.top is not None:
        problems += _against_model(parts, parts.top[2])
    return diagnostics(parts.path, text, problems)


def _against_model(parts: Parts, path: Path) -> list[Problem]:
    if not path.is_file():
        return [Problem(("model",), f"no such file: {path}")]
    try:
        model = mujoco.MjModel.from_xml_path(str(path))
    except ValueError as e:
        why = "; ".join(line.strip() for line in str(e).splitlines() if line.strip())
        return [Problem(("model",), f"MuJoCo cannot compile it: {why}")]
    return resolve(parts, model)


def require_folder(arg: str) -> Path:
    """``arg`` as a robot folder (or its robot.toml); a one-line error if it is neither."""
    path = Path(arg)
    if path.is_file() and path.name == "robot.toml":
        path = path.parent
    if not path.is_dir():
        raise DialError(f"{arg}: no such robot folder")
    return path
