"""A sweep worker's compiled models: each model file compiled once per worker process.

Every trial builds its simulation from scratch: the scene's MJCF (about 20 ms to
compile) and the robot-only model of each of the two IK solvers (about 3 ms each).
A worker runs many trials of the same scene, so :func:`install` makes the engine
take its models from this cache instead: each file is compiled once, and each
trial gets its own copy (0.5 ms). A trial may change its model (``--perturb``
moves the fixed objects) and starts from a fresh ``MjData`` as before, so the
results are the same with and without the cache.

Only a sweep's workers install it (``dial tune`` gives :func:`install` to its executor
as the worker initializer): they live for one sweep. MuJoCo is imported there only,
so the parent process needs none. The key includes the file's modification time, so
an edited scene file is compiled again; an edited file that it includes is not.
"""

from __future__ import annotations

import copy
import os
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import mujoco

# What a worker of an engine sweep imports: a fork server imports it once for all of them.
PRELOAD = ("dial.engine", "dial.parser.check", "dial.scene", "dial.tune.models")

_compiled: dict[tuple[str, int], mujoco.MjModel] = {}


def load_model(path: str | Path | None = None) -> mujoco.MjModel:
    """A copy of ``dial.backend.model.load_model(path)``, compiled once per process."""
    from dial.backend import model as robot_model

    path = robot_model.ROBOT_XML if path is None else path
    key = (str(path), os.stat(path).st_mtime_ns)
    model = _compiled.get(key)
    if model is None:
        model = _compiled[key] = robot_model.load_model(path)
    return copy.copy(model)


def compiled() -> int:
    """How many model files this process has compiled through the cache."""
    return len(_compiled)


def install() -> None:
    """Make the engine and the IK solvers load their models through the cache (idempotent)."""
    import dial.backend.ik
    import dial.engine

    # The names each module imported from dial.backend.model: patched in this process only.
    dial.engine.load_model = load_model  # type: ignore[attr-defined]
    dial.backend.ik.load_model = load_model  # type: ignore[attr-defined]
