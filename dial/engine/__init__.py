"""The engine: a checked script run in its scene, on the MuJoCo robot."""

from dial.engine.observe import Observer, StateLog, Watched
from dial.engine.result import Criteria, RunResult
from dial.engine.run import RunOptions, run, tick_length
from dial.scheduler.types import DEFAULT_TICK

__all__ = [
    "DEFAULT_TICK",
    "Criteria",
    "Observer",
    "RunOptions",
    "RunResult",
    "StateLog",
    "Watched",
    "run",
    "tick_length",
]
