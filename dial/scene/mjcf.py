"""Read a scene's MJCF model without MuJoCo: is it well-formed, and which bodies does it name?

``dial check`` uses this to report a malformed model, or a world object that names no body
of it, before anything runs. Includes are followed as MuJoCo follows them (relative to the
top-level file, or the robot's folder by name for a scene elsewhere, as dial's loader hands
MuJoCo the robot's files), and so are models attached with a name prefix
(``<attach model=... prefix=...>``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from dial.scene.reader import WorldFileError
from dial.scene.resolve import ROBOT_DIR, models_dir

_MAX_FILES = 200  # includes and attached models followed for one scene


class _Reader:
    """The bodies of a model and of everything it includes or attaches."""

    def __init__(self, top: Path, robot: Path) -> None:
        self.dirs = (top.parent, robot)
        self.files = 0
        self.models: dict[str, tuple[str, Path]] = {}  # <asset><model>: name -> (file, referrer)
        self.attaches: list[tuple[str, str, str, Path]] = []  # model, body, prefix, referrer

    def find(self, name: str, referrer: Path) -> Path:
        path = Path(name)
        candidates = [path] if path.is_absolute() else [d / path for d in self.dirs]
        candidates.append(referrer.parent / path)
        found = next((c for c in candidates if c.is_file()), None)
        if found is None:
            raise WorldFileError(referrer, "", f"model file '{name}' not found")
        return found.resolve()

    def parse(self, path: Path) -> ET.Element:
        self.files += 1
        if self.files > _MAX_FILES:
            raise WorldFileError(path, "", f"more than {_MAX_FILES} model files")
        try:
            return ET.parse(path).getroot()
        except ET.ParseError as e:
            line, col = e.position
            where = f"line {line}, column {col + 1}"
            raise WorldFileError(path, "", f"malformed XML at {where}") from None
        except OSError as e:
            raise WorldFileError(path, "", f"cannot read the model: {e.strerror}") from None

    def bodies(self, path: Path, chain: tuple[Path, ...] = ()) -> set[str]:
        """The bodies of ``path`` and its includes; attachments are noted for later."""
        if path in chain:
            raise WorldFileError(path, "", "include cycle: " + " -> ".join(p.name for p in chain))
        root = self.parse(path)
        names = {b.get("name", "") for b in root.iter("body")} - {""}
        for asset in root.iter("asset"):
            for m in asset.iter("model"):
                self.models[m.get("name", "")] = (m.get("file", ""), path)
        for att in root.iter("attach"):
            self.attaches.append(
                (att.get("model", ""), att.get("body", ""), att.get("prefix", ""), path)
            )
        for inc in root.iter("include"):
            names |= self.bodies(self.find(inc.get("file", ""), path), (*chain, path))
        return names

    def attached(self) -> set[str]:
        """The bodies that ``<attach>`` brings in, with their prefixes."""
        names: set[str] = set()
        for model, body, prefix, referrer in self.attaches:
            if model not in self.models:
                raise WorldFileError(referrer, "", f"<attach> names no <model> '{model}'")
            file, where = self.models[model]
            root = self.parse(self.find(file, where))
            top = next((b for b in root.iter("body") if b.get("name") == body), None)
            if top is None:
                raise WorldFileError(referrer, "", f"<attach> names no body '{body}' of '{file}'")
            names |= {prefix + b.get("name", "") for b in top.iter("body") if b.get("name")}
        return names


def body_names(model: Path, robot: Path | None = None) -> frozenset[str]:
    """Every named body of the MJCF model at ``model`` and what it includes or attaches;
    a file it names by bare name may be in the ``robot`` folder (default: the default
    robot's).

    Raises :class:`~dial.scene.reader.WorldFileError` for a file that is missing or
    malformed, naming it and the place.
    """
    reader = _Reader(model.resolve(), models_dir() / ROBOT_DIR if robot is None else robot)
    names = reader.bodies(model.resolve())
    return frozenset(names | reader.attached())
