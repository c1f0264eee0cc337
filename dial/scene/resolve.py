"""Where scenes live, and how ``@scene NAME_OR_PATH`` finds a world file.

A scene is entered through its **world file** (TOML), which names the MJCF model it runs on.
Bundled world files are ``<models_dir>/utah_hand_puma/worlds/<name>.toml``.
"""

from __future__ import annotations

from contextlib import suppress
from pathlib import Path

from dial.instructions.scene_names import SceneNotFoundError
from dial.resources import data_dir

ROBOT_DIR = "utah_hand_puma"
# The shared hand-pose file sits beside the world files but is not a scene.
POSES_FILE = "hand_poses.toml"


def models_dir() -> Path:
    """The model directory: ``dial/_data/models`` if installed, else the checkout's ``models/``."""
    return data_dir("models")


def worlds_dir() -> Path:
    """Directory of the bundled world files."""
    return models_dir() / ROBOT_DIR / "worlds"


def bundled_scene_names() -> tuple[str, ...]:
    """Names of the bundled scenes, sorted."""
    return tuple(sorted(p.stem for p in worlds_dir().glob("*.toml") if p.name != POSES_FILE))


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
    names = bundled_scene_names()
    if scene in names:
        return worlds_dir() / f"{scene}.toml"
    raise SceneNotFoundError(
        f"unknown scene '{scene}': neither a file (relative to the script) nor a bundled "
        f"scene; bundled scenes: {', '.join(names)}"
    )


def scene_option(arg: str, option: str = "--scene") -> str:
    """``--scene`` as every script it reaches should see it: an existing world file (as an
    absolute path, so that it means the same from every called script) or a bundled name.
    Raises :class:`SceneNotFoundError` listing the bundled names; ``option`` names the
    argument in it."""
    if Path(arg).is_file():
        return str(Path(arg).resolve())
    names = bundled_scene_names()
    if arg not in names:
        raise SceneNotFoundError(
            f"{option}: '{arg}' is neither a file nor a bundled scene; "
            f"bundled scenes: {', '.join(names)}"
        )
    return arg
