"""Where scenes live, and how ``@scene NAME_OR_PATH`` finds a world file.

A scene is entered through its **world file** (TOML), which names the MJCF model it runs on
and the robot it binds the script to. Bundled world files live in each bundled robot's
folder, ``<models_dir>/<robot>/worlds/<name>.toml``: the default robot's scenes by their
name (``pour``), every robot's as ``<robot>/<name>`` (``allegro_panda/pour``).
"""

from __future__ import annotations

from contextlib import suppress
from pathlib import Path

from dial.instructions.scene_names import SceneNotFoundError
from dial.resources import data_dir
from dial.robots.profile import DEFAULT_ROBOT, FILE

ROBOT_DIR = DEFAULT_ROBOT  # the default robot: a world file that names none runs on it
ROBOT_FILE = FILE
# The shared hand-pose file sits beside the world files but is not a scene.
POSES_FILE = "hand_poses.toml"


def models_dir() -> Path:
    """The model directory: ``dial/_data/models`` if installed, else the checkout's ``models/``."""
    return data_dir("models")


def worlds_dir(robot: str = ROBOT_DIR) -> Path:
    """Directory of a bundled robot's world files (the default robot's by default)."""
    return models_dir() / robot / "worlds"


def bundled_robot_names() -> tuple[str, ...]:
    """The bundled robots: the default first, then by name."""
    names = sorted(p.parent.name for p in models_dir().glob(f"*/{ROBOT_FILE}"))
    return tuple(sorted(names, key=lambda n: (n != ROBOT_DIR, n)))


def _scenes(robot: str) -> list[str]:
    return sorted(p.stem for p in worlds_dir(robot).glob("*.toml") if p.name != POSES_FILE)


def bundled_scene_names() -> tuple[str, ...]:
    """Names of the bundled scenes: the default robot's, then ``robot/name`` for the others."""
    names = _scenes(ROBOT_DIR)
    for robot in bundled_robot_names():
        if robot != ROBOT_DIR:
            names += [f"{robot}/{name}" for name in _scenes(robot)]
    return tuple(names)


def bundled_world(name: str) -> Path | None:
    """The world file of a bundled scene name (``pour``, ``allegro_panda/pour``, also
    ``utah_hand_puma/pour``), or None."""
    robot, _, scene = name.rpartition("/")
    if robot and robot not in bundled_robot_names():
        return None
    if "/" in scene or scene in ("", POSES_FILE.removesuffix(".toml")):
        return None
    path = worlds_dir(robot or ROBOT_DIR) / f"{scene}.toml"
    return path if path.is_file() else None


def bundled_name(path: Path) -> str | None:
    """The bundled scene name of a world file, or None if it is not a bundled scene."""
    path = path.resolve()
    for robot in bundled_robot_names():
        if path.parent == worlds_dir(robot).resolve() and path.name != POSES_FILE:
            return path.stem if robot == ROBOT_DIR else f"{robot}/{path.stem}"
    return None


def resolve_scene(scene: str, base_dir: Path) -> Path:
    """The world file that ``@scene scene`` means, for a script in ``base_dir``.

    An existing file (absolute, or relative to ``base_dir``) wins; otherwise ``scene`` must be
    a bundled scene name. Raises :class:`SceneNotFoundError` listing the bundled names.
    """
    candidate = Path(scene)
    with suppress(RuntimeError):  # '~user' of no such user: not a path; perhaps a bundled name
        candidate = candidate.expanduser()
    if not candidate.is_absolute():
        candidate = base_dir / candidate
    if candidate.is_file():
        return candidate
    bundled = bundled_world(scene)
    if bundled is not None:
        return bundled
    raise SceneNotFoundError(
        f"unknown scene '{scene}': neither a file (relative to the script) nor a bundled "
        f"scene; bundled scenes: {', '.join(bundled_scene_names())}"
    )


def scene_option(arg: str, option: str = "--scene") -> str:
    """``--scene`` as every script it reaches should see it: an existing world file (as an
    absolute path, so that it means the same from every called script) or a bundled name.
    Raises :class:`SceneNotFoundError` listing the bundled names; ``option`` names the
    argument in it."""
    if Path(arg).is_file():
        return str(Path(arg).resolve())
    if bundled_world(arg) is None:
        raise SceneNotFoundError(
            f"{option}: '{arg}' is neither a file nor a bundled scene; "
            f"bundled scenes: {', '.join(bundled_scene_names())}"
        )
    return arg
