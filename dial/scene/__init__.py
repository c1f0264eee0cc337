"""Scenes: resolving ``@scene``, and the world files that name poses, locations and programs.

Everything here is pure Python. The parts that need MuJoCo live in their own modules:
``dial.scene.evaluate`` (success criteria) and ``dial.scene.thread`` (the bulb's thread).
"""

from dial.scene.criteria import (
    Above,
    Criterion,
    FingerContacts,
    FractionInRegion,
    PlaneFit,
    SuperquadricFit,
    Upright,
)
from dial.scene.reader import WorldFileError
from dial.scene.resolve import bundled_scene_names, models_dir, resolve_scene, worlds_dir
from dial.scene.valii import Appro, Depart, Drive, Move, Statement, StatementError, parse_statement
from dial.scene.world import (
    HandPose,
    Location,
    Program,
    World,
    load_scene_names,
    load_world,
)

__all__ = [
    "Above",
    "Appro",
    "Criterion",
    "Depart",
    "Drive",
    "FingerContacts",
    "FractionInRegion",
    "HandPose",
    "Location",
    "Move",
    "PlaneFit",
    "Program",
    "Statement",
    "StatementError",
    "SuperquadricFit",
    "Upright",
    "World",
    "WorldFileError",
    "bundled_scene_names",
    "load_scene_names",
    "load_world",
    "models_dir",
    "parse_statement",
    "resolve_scene",
    "worlds_dir",
]
