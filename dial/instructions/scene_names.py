"""What the checker needs to know about a scene: the names its world file defines.

This is the seam between the pure-Python checker and the scene/world-file loader
(``dial.scene``). The checker never reads world files itself; it asks a
:data:`SceneLoader` for a :class:`SceneNames`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from dial.errors import DialError
from dial.robots.facts import RobotFacts


@dataclass(frozen=True)
class SceneNames:
    """Names a scene's world file defines.

    ``poses`` maps each named hand pose to the 16-bit joint mask it sets
    (bit ``4*f + j``; a pose that sets every joint has mask ``0xFFFF``). ``anchored``: the
    locations that are relative to an object; ``objects``: the object aliases; ``robot``:
    what the scene's robot has (None: the default robot).
    """

    name: str
    poses: Mapping[str, int] = field(default_factory=dict)
    locations: frozenset[str] = frozenset()
    programs: frozenset[str] = frozenset()
    objects: frozenset[str] = frozenset()
    anchored: frozenset[str] = frozenset()
    robot: RobotFacts | None = None


class SceneNotFoundError(DialError, LookupError):
    """The ``@scene`` argument names no bundled scene and no existing path.

    The message lists the valid bundled scene names.
    """


# (scene name or path as written in ``@scene``, directory of the script) -> names.
# Raises SceneNotFoundError, or ValueError for a world file that is malformed.
SceneLoader = Callable[[str, Path], SceneNames]
