"""The instructions: each declared once, in its own module that the catalogue lists."""

from dial.instructions.base import Args, Instruction, ParamSpec
from dial.instructions.catalogue import INSTRUCTIONS
from dial.instructions.scene_names import SceneLoader, SceneNames, SceneNotFoundError

__all__ = [
    "INSTRUCTIONS",
    "Args",
    "Instruction",
    "ParamSpec",
    "SceneLoader",
    "SceneNames",
    "SceneNotFoundError",
]
