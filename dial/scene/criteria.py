"""Success criteria declared in world files (pure data; evaluation is in ``dial.scene.evaluate``).

Each ``[criteria.NAME]`` table has a ``kind`` and that kind's keys. ``object`` keys name an
object alias of the world file (``[objects]``) and are stored as the MuJoCo body name.
Angles are written in degrees and stored in radians; lengths are metres.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import MISSING, Field, dataclass, field, fields
from typing import Any, ClassVar, get_type_hints

from dial.robots.fields import value_kind
from dial.scene.reader import Reader

FACES: tuple[str, ...] = ("+x", "-x", "+y", "-y", "+z", "-z")
SHAPES: tuple[str, ...] = ("box", "cylinder", "rounded")


@dataclass(frozen=True)
class Criterion:
    """Base of the criteria: a name, unique in its world file."""

    kind: ClassVar[str]
    name: str

    def check(self) -> str | None:
        """What is wrong with the values, or ``None``."""
        return None


@dataclass(frozen=True)
class FractionInRegion(Criterion):
    """At least ``min`` of the bodies matching glob ``bodies`` lie in the box site ``region``."""

    kind = "fraction_in_region"
    bodies: str
    region: str
    min: float

    def check(self) -> str | None:
        return None if 0.0 < self.min <= 1.0 else "min must be a fraction in (0, 1]"


@dataclass(frozen=True)
class Upright(Criterion):
    """The object's z axis is within ``max_tilt`` of world +z."""

    kind = "upright"
    body: str = field(metadata={"key": "object"})
    max_tilt: float = field(default=math.radians(10.0), metadata={"key": "max_tilt_deg"})

    def check(self) -> str | None:
        return None if 0.0 < self.max_tilt < math.pi else "max_tilt_deg must be in (0, 180)"


@dataclass(frozen=True)
class Above(Criterion):
    """The object's origin is at least ``min_height`` m above the site ``site``."""

    kind = "above"
    body: str = field(metadata={"key": "object"})
    site: str
    min_height: float


@dataclass(frozen=True)
class FingerContacts(Criterion):
    """At least ``min`` fingers touch the object, pressing it with at most ``max_force`` N of
    normal contact force in all (a light touch, not a crash). A finger is every body whose
    name starts with one of ``fingers`` (body-name prefixes, one per finger)."""

    kind = "finger_contacts"
    body: str = field(metadata={"key": "object"})
    fingers: tuple[str, ...]
    min: int = 2
    max_force: float = math.inf

    def check(self) -> str | None:
        if not 1 <= self.min <= len(self.fingers):
            return f"min must be from 1 to the number of fingers ({len(self.fingers)})"
        return None if self.max_force > 0 else "max_force must be above 0 N"


@dataclass(frozen=True)
class PlaneFit(Criterion):
    """The plane fitted to point set ``set`` matches face ``face`` of the object's solid: normal
    within ``normal_tol``, and each traced extent within ``extent_tol`` of the face's size."""

    kind = "plane_fit"
    set: str
    body: str = field(metadata={"key": "object"})
    face: str = field(default="+z", metadata={"choices": FACES})
    normal_tol: float = field(default=math.radians(2.0), metadata={"key": "normal_tol_deg"})
    extent_tol: float = 0.005

    def check(self) -> str | None:
        return None if self.normal_tol > 0 and self.extent_tol > 0 else "tolerances must be > 0"


@dataclass(frozen=True)
class SuperquadricFit(Criterion):
    """The superquadric fitted to point set ``set`` has the object's half-sizes to within the
    relative ``size_tol``, and its exponents classify as the object's shape."""

    kind = "superquadric_fit"
    set: str
    body: str = field(metadata={"key": "object"})
    size_tol: float = 0.10

    def check(self) -> str | None:
        return None if 0.0 < self.size_tol < 1.0 else "size_tol must be a fraction in (0, 1)"


KINDS: dict[str, type[Criterion]] = {
    c.kind: c for c in (FractionInRegion, Upright, Above, FingerContacts, PlaneFit, SuperquadricFit)
}


def parse_criterion(
    reader: Reader, name: str, table: Mapping[str, Any], objects: Mapping[str, str]
) -> Criterion:
    """Build one criterion from its TOML table; ``objects`` maps aliases to body names."""
    key = f"criteria.{name}"
    if not isinstance(table, Mapping):
        got = value_kind(table)
        raise reader.error(key, f"expected a table, or false to drop an extended file's; got {got}")
    kind = reader.choice(table.get("kind"), f"{key}.kind", KINDS, "criterion kind")
    cls = KINDS[kind]
    hints = get_type_hints(cls)
    spec = [f for f in fields(cls) if f.name != "name"]
    toml_key = {f.name: f.metadata.get("key", f.name) for f in spec}
    required = [toml_key[f.name] for f in spec if _required(f)]
    optional = ["kind", *(toml_key[f.name] for f in spec if not _required(f))]
    reader.keys(table, key, required, optional)
    values: dict[str, Any] = {}
    for f in spec:
        k = toml_key[f.name]
        if k not in table:
            continue
        raw, where = table[k], f"{key}.{k}"
        if k == "object":
            values[f.name] = objects[reader.choice(raw, where, objects, "object")]
        elif "choices" in f.metadata:
            values[f.name] = reader.choice(raw, where, f.metadata["choices"], k)
        elif k.endswith("_deg"):
            values[f.name] = math.radians(reader.number(raw, where))
        else:
            values[f.name] = _read(reader, hints[f.name], raw, where)
    criterion = cls(name=name, **values)
    problem = criterion.check()
    if problem is not None:
        raise reader.error(key, problem)
    return criterion


def _required(f: Field[Any]) -> bool:
    return f.default is MISSING and f.default_factory is MISSING


def _read(reader: Reader, hint: Any, raw: Any, where: str) -> Any:
    if hint is float:
        return reader.number(raw, where)
    if hint is int:
        return reader.integer(raw, where)
    if hint is str:
        return reader.string(raw, where)
    return reader.strings(raw, where)  # tuple[str, ...]
