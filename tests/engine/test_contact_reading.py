"""One contact reading: the guards' per-step form and a contact wait's snapshot form agree,
bit for bit, with each other and with the definition (DESIGN 3), on random states of every
scene: joint angles and set-points, tendon tensions, taxel depths, baselines and dropouts.

Tripling the position reading in ``dial/backend/guards.py`` (or any other change to one of
the forms alone) fails this test.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

pytest.importorskip(
    "hypothesis", reason="the 'test' extra is not installed: pip install -e '.[test]'"
)
from hypothesis import given, settings
from hypothesis import strategies as st

from dial.backend.driver import MujocoRobot
from dial.backend.guards import Readings
from dial.backend.model import load_model, profile_at
from dial.instructions.types import CONTACT_KINDS, FINGERS, Contact, ContactKind
from dial.primitives.sensing import contact_value
from dial.robot.contact import POSITION_LEVER
from dial.scene.resolve import bundled_scene_names, resolve_scene, worlds_dir
from dial.scene.world import load_world

SCENES = bundled_scene_names()
_robots: dict[str, MujocoRobot] = {}


def _robot(scene: str) -> MujocoRobot:
    """The scene's robot (its model compiled once per test session)."""
    if scene not in _robots:
        world = load_world(resolve_scene(scene, worlds_dir()))
        profile = profile_at(world.robot)
        model = load_model(world.model_path, profile)
        _robots[scene] = MujocoRobot(model, mujoco.MjData(model), profile=profile)
    return _robots[scene]


def _definition(
    kind: ContactKind,
    f: int,
    robot: MujocoRobot,
    baseline: list[float],
    dropped: frozenset[tuple[str, int]],
) -> float:
    """DESIGN 3's readings, written plainly from the physics: the deepest taxel; the largest
    change of the finger's joint loads (tendon differentials, or joint torques over the
    profile's lever); its joint error times the lever."""
    if (kind, f) in dropped:
        return 0.0
    d, ix = robot.data, robot.index
    joints = slice(4 * f, 4 * f + 4)
    if kind == "tactile":
        a = int(ix.tactile_sensors[f])
        return float(np.max(d.sensordata[a : a + 256]))
    if kind == "force":
        raw = d.sensordata[ix.load_sensors]
        loads = raw[0::2] - raw[1::2] if ix.tendons else raw / ix.lever
        change = loads - np.array(baseline)
        return float(np.abs(change[joints]).max())
    error = robot.hand_target[joints] - d.qpos[ix.hand_qpos][joints]
    return float(np.linalg.norm(error)) * POSITION_LEVER


@st.composite
def states(draw: st.DrawFn) -> tuple[str, int]:
    """A scene and a seed for its random state."""
    return draw(st.sampled_from(SCENES)), draw(st.integers(0, 2**31 - 1))


def _randomize(robot: MujocoRobot, seed: int) -> tuple[list[float], frozenset[tuple[str, int]]]:
    """Random joint angles, set-points, tensions and taxels (sparse, as touches are); a
    random baseline and random dropouts."""
    rng = np.random.default_rng(seed)
    d, ix = robot.data, robot.index
    lo, hi = robot.view.hand_range.T
    d.qpos[ix.hand_qpos] = rng.uniform(lo, hi)
    robot.hand_target = rng.uniform(lo - 0.1, hi + 0.1)
    n = len(ix.load_sensors)
    d.sensordata[ix.load_sensors] = (
        rng.uniform(0.0, 50.0, n) if ix.tendons else rng.uniform(-0.7, 0.7, n)
    )
    for a in ix.tactile_sensors:
        touched = rng.random(256) < rng.choice([0.0, 0.05, 0.5])
        d.sensordata[a : a + 256] = np.where(touched, rng.uniform(0.0, 0.003, 256), 0.0)
    baseline = rng.uniform(-20.0, 20.0, 16).tolist()
    every = [(kind, f) for kind in CONTACT_KINDS for f in range(len(FINGERS))]
    dropped = frozenset(p for p in every if rng.random() < 0.15)
    robot.disturbances.dropped = dropped
    return baseline, dropped


@settings(max_examples=60, deadline=None)
@given(states())
def test_a_guard_and_a_wait_read_the_same_contact(state: tuple[str, int]) -> None:
    scene, seed = state
    robot = _robot(scene)
    baseline, dropped = _randomize(robot, seed)
    robot.steps += 1  # a new state: the snapshot reads it afresh
    snapshot = robot.snapshot()
    tactile = [int(a) for a in robot.index.tactile_sensors]
    readings = Readings(robot.data, robot.index, tactile).at_step(robot.hand_target, dropped)
    for kind in CONTACT_KINDS:
        for f in range(len(FINGERS)):
            guard = readings.value(kind, f, baseline)
            wait = contact_value(Contact(kind, f, 0.0), snapshot, baseline)
            where = f"{scene} seed {seed}: {kind} on finger {f}"
            assert guard == wait, where
            assert guard == _definition(kind, f, robot, baseline, dropped), where
