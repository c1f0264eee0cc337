"""What a sweep's worker process sets up once: its imports and its compiled models.

Every trial builds its simulation from scratch, from the scene's MJCF and the robot-only
model of each IK solver. A worker runs many trials of the same scene, so :func:`install`
(the executor's worker initializer) makes it compile each model file once and give each
trial its own copy (``dial.backend.model.keep_compiled``); results are the same. MuJoCo
is imported in the workers only, so the parent process needs none.
"""

from __future__ import annotations

# What a worker of an engine sweep imports: a fork server imports it once for all of them.
PRELOAD = ("dial.engine", "dial.parser.check", "dial.scene", "dial.tune.models")


def install() -> None:
    """Keep this process's compiled models for its later trials (idempotent)."""
    from dial.backend import model

    model.keep_compiled()
