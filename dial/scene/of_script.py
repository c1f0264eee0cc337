"""The world a checked script runs in, and the bodies its options may name, without MuJoCo.

``dial run`` finds a bad ``--disturb`` body on the compiled model; ``dial tune`` checks
here, from the model's XML, so a typo is one usage error before any trial starts.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from dial.disturb import Disturbance, DisturbanceError, Push
from dial.errors import DialError
from dial.parser.script import Script
from dial.scene.mjcf import body_names
from dial.scene.resolve import resolve_scene
from dial.scene.world import World, load_world


def script_world(script: Script) -> World:
    """The world the script runs in: ``--scene``, else its ``@scene``."""
    scene = script.program.scene
    text = script.scene_override or (scene.text if scene is not None else None)
    if text is None:
        raise DialError(
            f"{script.path}: the script names no scene; add '@scene NAME' or run it with --scene"
        )
    return load_world(resolve_scene(text, Path(script.path).resolve().parent))


def check_pushes(items: Sequence[Disturbance], world: World) -> None:
    """Raise :class:`DisturbanceError`, listing the valid names, for a push that names no
    body of ``world``'s model."""
    pushes = [d for d in items if isinstance(d, Push)]
    if not pushes:
        return
    bodies = body_names(world.model_path, world.robot)
    for push in pushes:
        if push.body not in bodies:
            raise DisturbanceError(
                f"--disturb '{push.text}': no body '{push.body}' in this scene; "
                f"valid bodies: {', '.join(sorted(bodies))}"
            )
