"""dial: run DIAL-style tick-based timeline scripts on a simulated robot hand and arm (the
Utah/MIT hand on a PUMA 560, an Allegro-like hand on a Panda-like arm, or another robot).

The public API (docs/api.md)::

    import dial

    result = dial.run(dial.load("pour.dial"), perturb=10, seed=3)
    print(result.ok, result.success)

``import dial`` loads nothing but this file (with ``dial.lazy``, and ``dial.codecache``, which
keeps the compiled code of dial's dataclasses in the user's cache): each name below is
imported from its module on first use (``dial.load`` brings the parser, ``dial.run`` the
engine, MuJoCo on the first run), so that ``dial --help`` and ``dial check`` start quickly
(docs/architecture.md).
"""

from typing import TYPE_CHECKING

from dial import codecache
from dial.lazy import lazy_names

codecache.install()  # before any module of dial makes a dataclass

if TYPE_CHECKING:
    from dial.api import load, run, save_world
    from dial.engine import Observer, RunResult, Watched
    from dial.errors import Diagnostic, DialError, OptionError, ScriptError, Span
    from dial.parser.script import Script

__version__ = "0.1.0"
__all__ = [
    "Diagnostic",
    "DialError",
    "Observer",
    "OptionError",
    "RunResult",
    "Script",
    "ScriptError",
    "Span",
    "Watched",
    "__version__",
    "load",
    "run",
    "save_world",
]
# Where each public name lives.
_HOMES = {
    "load": "dial.api",
    "run": "dial.api",
    "save_world": "dial.api",
    "Diagnostic": "dial.errors",
    "DialError": "dial.errors",
    "OptionError": "dial.errors",
    "ScriptError": "dial.errors",
    "Span": "dial.errors",
    "Script": "dial.parser.script",
    "Observer": "dial.engine",
    "RunResult": "dial.engine",
    "Watched": "dial.engine",
}

__getattr__ = lazy_names(__name__, _HOMES)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
