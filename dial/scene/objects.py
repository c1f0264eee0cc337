"""A world file's ``[objects]``: aliases for MuJoCo bodies, and what is believed of them.

An entry is the body's name (``pitcher = "pour_pitcher"``), or a table that also says where
the world model believes the object is and how large: ``{ body = "pour_pitcher", pos =
[0.59, -0.12, 0.35], rpy = [0, 0, 0], size = [0.05, 0.05, 0.075] }`` (m, deg, half-sizes
along the body's axes). ``dial run --save-world`` writes such tables; without them the
world model believes each object is where the model puts it, its size unknown.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from dial.scene.reader import Reader
from dial.scene.valii import NAME


@dataclass(frozen=True)
class Prior:
    """What a world file says the world model believes of an object at load, beyond its body:
    its pose (``pos`` m, ``rpy`` rad as for locations; None: where the model has it) and its
    half-sizes along its body axes (m; None: not known). ``dial run --save-world`` writes
    them (see :mod:`dial.scene.belief`)."""

    pos: tuple[float, float, float] | None = None
    rpy: tuple[float, float, float] | None = None
    size: tuple[float, float, float] | None = None


def parse_objects(reader: Reader, value: Any) -> tuple[dict[str, str], dict[str, Prior]]:
    """Aliases -> bodies, and bodies -> what is believed of them: an entry is the body's
    name, or a table ``{ body = "...", pos = [...], rpy = [...], size = [...] }``."""
    table = reader.table(value, "objects")
    if not table:
        raise reader.error("objects", 'declare at least one object (alias = "body_name")')
    objects: dict[str, str] = {}
    priors: dict[str, tuple[str, Prior]] = {}  # body -> (the alias that set it, the prior)
    for alias, entry in table.items():
        key = f"objects.{_alias(reader, alias)}"
        if isinstance(entry, str):
            objects[alias] = entry
            continue
        fields = reader.table(entry, key)
        reader.keys(fields, key, ["body"], ["pos", "rpy", "size"])
        objects[alias] = body = reader.string(fields["body"], f"{key}.body")
        prior = _prior(reader, key, fields)
        if body in priors and priors[body][1] != prior:
            raise reader.error(key, f"believed differently by objects.{priors[body][0]}")
        priors[body] = (alias, prior)
    return objects, {body: prior for body, (_, prior) in priors.items()}


def _prior(reader: Reader, key: str, fields: Mapping[str, Any]) -> Prior:
    pos = rpy = size = None
    if "pos" in fields:
        x, y, z = reader.vector(fields["pos"], f"{key}.pos", 3)
        pos = (x, y, z)
    if "rpy" in fields:
        r, p, w = (math.radians(a) for a in reader.vector(fields["rpy"], f"{key}.rpy", 3))
        rpy = (r, p, w)
    if "size" in fields:
        a, b, c = reader.vector(fields["size"], f"{key}.size", 3)
        if min(a, b, c) <= 0.0:
            raise reader.error(f"{key}.size", "half-sizes must be more than 0 m")
        size = (a, b, c)
    return Prior(pos, rpy, size)


def _alias(reader: Reader, name: str) -> str:
    if not NAME.match(name):
        raise reader.error(f"objects.{name}", "invalid name: expected [A-Za-z_][A-Za-z0-9_]*")
    return name
