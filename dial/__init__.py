"""dial: run DIAL-style tick-based timeline scripts on a simulated robot hand and arm (the
Utah/MIT hand on a PUMA 560, an Allegro-like hand on a Panda-like arm, or another robot).

The public API (docs/api.md)::

    import dial

    result = dial.run(dial.load("pour.dial"), perturb=10, seed=3)
    print(result.ok, result.success)

``dial.load`` and ``dial.run`` are light to import; MuJoCo loads on the first run.
"""

from typing import TYPE_CHECKING

from dial.api import load, run, save_world
from dial.errors import Diagnostic, DialError, OptionError, ScriptError, Span
from dial.parser.script import Script

if TYPE_CHECKING:
    from dial.engine import Observer, RunResult, Watched

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
_ENGINE = ("Observer", "RunResult", "Watched")


def __getattr__(name: str) -> object:
    """``dial.RunResult`` and the observer types, imported with the engine when first used."""
    if name in _ENGINE:
        import dial.engine

        return getattr(dial.engine, name)
    raise AttributeError(f"module 'dial' has no attribute '{name}'")
