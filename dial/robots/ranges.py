"""Joint ranges read from a robot's MJCF without MuJoCo, for the checks that run before any
simulator does (``dial check``: a hand pose beyond a joint's range, a DRIVE beyond the arm's).

The reader follows what MuJoCo's compiler does for the attributes it needs: includes inlined,
default classes (``<default class>``, nested, with ``class`` and ``childclass``), the
compiler's ``angle`` unit, and models attached with a name prefix (``<attach>``), each with its
own defaults and units. ``tests/robots`` checks that it agrees with MuJoCo on every bundled
robot.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from dial.errors import DialError

Range = tuple[float, float]
_COMMENT = re.compile(r"<!--.*?-->", re.DOTALL)
_MAX_DEPTH = 20  # includes and attachments inside one another


@dataclass
class _Model:
    """One MJCF file with its includes inlined: its defaults and its angle unit."""

    root: ET.Element
    path: Path
    classes: dict[str, tuple[str | None, dict[str, str]]]  # class -> parent, joint attributes
    degrees: bool


def _load(path: Path, dirs: tuple[Path, ...], depth: int = 0) -> _Model:
    root = _parse(path)
    _inline(root, path, dirs, depth)
    compilers = [c for c in root.iter("compiler") if c.get("angle")]
    degrees = (compilers[-1].get("angle") if compilers else "degree") == "degree"
    classes: dict[str, tuple[str | None, dict[str, str]]] = {}
    for top in root.findall("default"):
        _defaults(top, None, classes)
    return _Model(root, path, classes, degrees)


def _parse(path: Path) -> ET.Element:
    try:
        # Comments out first: MuJoCo's parser accepts "--" inside them, XML does not.
        return ET.fromstring(_COMMENT.sub("", path.read_text(encoding="utf-8")))
    except (ET.ParseError, OSError, UnicodeDecodeError) as e:
        raise DialError(f"{path}: cannot read the model: {e}") from None


def _find(name: str, referrer: Path, dirs: tuple[Path, ...]) -> Path:
    path = Path(name)
    candidates = (
        [path] if path.is_absolute() else [referrer.parent / path, *(d / path for d in dirs)]
    )
    found = next((c for c in candidates if c.is_file()), None)
    if found is None:
        raise DialError(f"{referrer}: model file '{name}' not found")
    return found


def _inline(element: ET.Element, path: Path, dirs: tuple[Path, ...], depth: int) -> None:
    """Replace every ``<include>`` under ``element`` by the included file's contents."""
    if depth > _MAX_DEPTH:
        raise DialError(f"{path}: includes nested more than {_MAX_DEPTH} deep")
    for i, child in enumerate(list(element)):
        if child.tag == "include":
            included = _find(child.get("file", ""), path, dirs)
            root = _parse(included)
            _inline(root, included, dirs, depth + 1)
            element.remove(child)
            for k, grandchild in enumerate(list(root)):
                element.insert(i + k, grandchild)
        else:
            _inline(child, path, dirs, depth)


def _defaults(
    element: ET.Element, parent: str | None, out: dict[str, tuple[str | None, dict[str, str]]]
) -> None:
    name = element.get("class", "main")
    joint = element.find("joint")
    out[name] = (parent, dict(joint.attrib) if joint is not None else {})
    for child in element.findall("default"):
        _defaults(child, name, out)


def _attribute(model: _Model, joint: ET.Element, cls: str, key: str) -> str | None:
    if key in joint.attrib:
        return joint.get(key)
    name: str | None = joint.get("class", cls)
    while name is not None and name in model.classes:
        parent, attrs = model.classes[name]
        if key in attrs:
            return attrs[key]
        name = parent if parent is not None else (None if name == "main" else "main")
    return None


def _walk(
    model: _Model,
    element: ET.Element,
    cls: str,
    prefix: str,
    dirs: tuple[Path, ...],
    out: dict[str, Range],
    depth: int,
) -> None:
    for child in element:
        if child.tag == "joint":
            _joint(model, child, cls, prefix, out)
        elif child.tag in ("body", "frame", "worldbody"):
            _walk(model, child, child.get("childclass", cls), prefix, dirs, out, depth)
        elif child.tag == "attach":
            _attach(model, child, prefix, dirs, out, depth)


def _joint(model: _Model, joint: ET.Element, cls: str, prefix: str, out: dict[str, Range]) -> None:
    kind = _attribute(model, joint, cls, "type") or "hinge"
    text = _attribute(model, joint, cls, "range")
    if kind not in ("hinge", "slide") or text is None or not joint.get("name"):
        return
    if _attribute(model, joint, cls, "limited") == "false":
        return
    lo, hi = (float(v) for v in text.split())
    if kind == "hinge" and model.degrees:
        lo, hi = math.radians(lo), math.radians(hi)
    out[prefix + joint.get("name", "")] = (lo, hi)


def _attach(
    model: _Model,
    attach: ET.Element,
    prefix: str,
    dirs: tuple[Path, ...],
    out: dict[str, Range],
    depth: int,
) -> None:
    if depth > _MAX_DEPTH:
        raise DialError(f"{model.path}: models attached more than {_MAX_DEPTH} deep")
    name = attach.get("model", "")
    asset = next((m for m in model.root.iter("model") if m.get("name") == name), None)
    if asset is None:
        raise DialError(f"{model.path}: <attach> names no <model> '{name}'")
    child = _load(_find(asset.get("file", ""), model.path, dirs), dirs, depth + 1)
    body = next((b for b in child.root.iter("body") if b.get("name") == attach.get("body")), None)
    if body is None:
        raise DialError(f"{child.path}: no body '{attach.get('body')}' to attach")
    wrapper = ET.Element("frame")
    wrapper.append(body)
    _walk(child, wrapper, "main", prefix + attach.get("prefix", ""), dirs, out, depth + 1)


def joint_ranges(model: Path, robot: Path | None = None) -> dict[str, Range]:
    """The range (rad for hinges, m for slides) of every limited joint of the MJCF ``model``,
    by its compiled name. Files it names by bare name may be in the ``robot`` folder."""
    dirs = (robot,) if robot is not None else ()
    loaded = _load(model.resolve(), dirs)
    out: dict[str, Range] = {}
    for worldbody in loaded.root.iter("worldbody"):
        _walk(loaded, worldbody, "main", "", dirs, out, 0)
    return out
