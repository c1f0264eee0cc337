"""The contact readings, defined once: a contact wait reads them from its snapshot
(:func:`dial.primitives.sensing.contact_value`), and a robot's guards and monitors read them
after every physics step (:class:`dial.backend.guards.Readings`), so that a guard, a monitor
and a wait mean the same contact. ``tests/engine/test_contact_reading.py`` checks that both
agree on random states of every scene.

Each is written in the form that the per-step test can afford, as it runs thousands of
times a run: Python floats where there are few values, and the deepest taxel through
``argmax``, which costs a quarter of ``max`` just after a physics step.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from dial.robot.snapshot import FloatArray

POSITION_LEVER = 0.1  # m: joint error (rad) to fingertip displacement, about a finger length


def tactile_reading(depths: FloatArray) -> float:
    """The deepest taxel of a fingertip's array (m); ``depths``: its taxel depths, any shape."""
    return float(depths.item(depths.argmax()))


def force_reading(loads: Sequence[float], baseline: Sequence[float], finger: int) -> float:
    """The largest change (N) of the finger's four joint loads from ``baseline`` (the 16 loads
    to measure from, mask order; zeros for their value). ``loads``: the 16 joint loads (N,
    mask order): a tendon hand's flexor minus extensor tension, another hand's joint torque
    over its lever (robot.toml ``hand.lever``), 0 for a joint the hand lacks."""
    return max(abs(loads[k] - baseline[k]) for k in range(4 * finger, 4 * finger + 4))


def position_reading(target: FloatArray, q: FloatArray, finger: int) -> float:
    """The finger's joint error (its set-points ``target`` minus its angles ``q``, (16,) rad,
    mask order) times the lever: about its fingertip's displacement (m)."""
    joints = slice(4 * finger, 4 * finger + 4)
    return float(np.linalg.norm(target[joints] - q[joints])) * POSITION_LEVER
