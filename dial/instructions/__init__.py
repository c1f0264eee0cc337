"""The instruction catalogue: what each instruction takes, commands and how long it runs."""

from dial.instructions.catalogue import INSTRUCTIONS, Instruction, ParamSpec
from dial.instructions.scene_names import SceneLoader, SceneNames, SceneNotFoundError

__all__ = [
    "INSTRUCTIONS",
    "Instruction",
    "ParamSpec",
    "SceneLoader",
    "SceneNames",
    "SceneNotFoundError",
]
