"""Where bundled scripts and models live, installed or in a source checkout.

A wheel installs them under ``dial/_data`` (see ``pyproject.toml``); a checkout
keeps them at the repository root. Scripts and scenes resolve as a path if it
exists, else as a bundled example by name.
"""

from __future__ import annotations

from pathlib import Path

from dial.errors import DialError

_PACKAGE = Path(__file__).resolve().parent


def data_dir(name: str) -> Path:
    """The bundled ``scripts`` or ``models`` directory."""
    for candidate in (_PACKAGE / "_data" / name, _PACKAGE.parent / name):
        if candidate.is_dir():
            return candidate
    raise DialError(f"bundled '{name}' directory is missing from this installation of dial")


def bundled_scripts() -> list[str]:
    return sorted(p.name for p in data_dir("scripts").glob("*.dial"))


def resolve_script(arg: str) -> Path:
    """``arg`` as a path if it exists, else a bundled script by name (``.dial`` optional)."""
    path = Path(arg)
    if path.is_file():
        return path
    name = path.name if path.suffix == ".dial" else path.name + ".dial"
    try:
        bundled = data_dir("scripts") / name
    except DialError:
        bundled = None
    if bundled is not None and bundled.is_file():
        return bundled
    valid = ", ".join(bundled_scripts())
    raise DialError(f"no such script '{arg}' (not a file, and not a bundled script: {valid})")
