"""Names a package exports but imports only when first used (PEP 562), so that importing
the package costs nothing until then (docs/architecture.md, "Start-up")."""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping
from importlib import import_module


def lazy_names(package: str, homes: Mapping[str, str]) -> Callable[[str], object]:
    """A ``__getattr__`` for ``package``: each name of ``homes`` (name -> the module that
    defines it) is imported from its module on first use, and kept in the package."""
    namespace = sys.modules[package].__dict__

    def __getattr__(name: str) -> object:
        home = homes.get(name)
        if home is None:
            raise AttributeError(f"module '{package}' has no attribute '{name}'")
        value = getattr(import_module(home), name)
        namespace[name] = value
        return value

    return __getattr__
