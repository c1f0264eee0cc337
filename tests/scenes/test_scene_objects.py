"""Object physics without the robot: pouring, the lid, the bulb's thread, resting solids."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from dial.scene import WorldFileError, load_world, worlds_dir
from dial.scene.thread import find_threads, set_turns

from .conftest import ObjectWorld, step, warnings, write

BALLS = [f"pour_ball_{k:02d}" for k in range(20)]
PITCH = 0.004  # m per turn
TURNS = 1.5


def _in_site(model: mujoco.MjModel, data: mujoco.MjData, bodies: list[str], site: str) -> int:
    ids = [model.body(b).id for b in bodies]
    s = model.site(site)
    local = (data.xpos[ids] - data.site_xpos[s.id]) @ data.site_xmat[s.id].reshape(3, 3)
    return int(np.all(np.abs(local) <= s.size, axis=1).sum())


# Pour -------------------------------------------------------------------------------------

GRIP = '<body name="grip" mocap="true" pos="0.59 -0.12 0.35"/>'
WELD = '<weld body1="grip" body2="pour_pitcher"/>'


def _asleep(model: mujoco.MjModel, data: mujoco.MjData, bodies: list[str]) -> int:
    trees = model.body_treeid[[model.body(b).id for b in bodies]]
    return int((data.tree_asleep[trees] >= 0).sum())


def test_balls_start_at_rest_and_sleep(object_world: ObjectWorld) -> None:
    model, data = object_world("pour")
    assert model.opt.enableflags & mujoco.mjtEnableBit.mjENBL_SLEEP
    ids = [model.body(b).id for b in BALLS]
    start = data.xpos[ids].copy()
    assert _asleep(model, data, BALLS) == 0
    step(model, data, 0.1)
    # The written positions are the resting ones: the pile sleeps at once, where it was put.
    pile = [*BALLS, "pour_pitcher", "pour_lid", "pour_cup"]
    assert _asleep(model, data, pile) == len(pile)
    assert np.abs(data.xpos[ids] - start).max() < 2e-4


def test_balls_stay_in_the_pitcher_at_rest(object_world: ObjectWorld) -> None:
    model, data = object_world("pour")
    assert _in_site(model, data, BALLS, "pour_pitcher_inside") == len(BALLS)
    step(model, data, 2.0)
    assert _in_site(model, data, BALLS, "pour_pitcher_inside") == len(BALLS)
    assert _asleep(model, data, BALLS) == len(BALLS)  # no ball spins on: damping stops it
    assert warnings(data) == 0


def test_a_spinning_ball_wakes_the_pile_and_it_sleeps_again(object_world: ObjectWorld) -> None:
    model, data = object_world("pour")
    step(model, data, 0.2)
    # Spin about the vertical: no contact of a ball resists it (frictionless neighbours, no
    # torsional friction on the floor), so only the joint damping can stop it.
    dof = model.jnt_dofadr[model.body("pour_ball_06").jntadr[0]]
    data.qvel[dof + 5] = 20.0
    step(model, data, 0.01)
    assert _asleep(model, data, BALLS) == 0
    step(model, data, 1.5)
    assert _asleep(model, data, BALLS) == len(BALLS)
    assert _in_site(model, data, BALLS, "pour_pitcher_inside") == len(BALLS)


def test_balls_pour_out_when_the_pitcher_tilts_120_degrees(object_world: ObjectWorld) -> None:
    model, data = object_world("pour", body=GRIP, equality=WELD)
    lid = model.joint("pour_lid").qposadr[0]
    data.qpos[lid : lid + 3] = (0.3, 0.6, 0.05)  # lid taken off, on the floor
    step(model, data, 0.5)
    for i in range(250):  # lift 15 cm in 0.5 s
        data.mocap_pos[0, 2] = 0.35 + 0.15 * (i + 1) / 250
        mujoco.mj_step(model, data)
    assert _in_site(model, data, BALLS, "pour_pitcher_inside") == len(BALLS)
    for i in range(500):  # tilt 120 degrees about x in 1 s, mouth toward +y
        half = -math.radians(120) * (i + 1) / 500 / 2
        data.mocap_quat[0] = (math.cos(half), math.sin(half), 0, 0)
        mujoco.mj_step(model, data)
    step(model, data, 1.0)
    assert _in_site(model, data, BALLS, "pour_pitcher_inside") <= 2
    assert warnings(data) == 0


def test_lid_lifts_off_freely(object_world: ObjectWorld) -> None:
    model, data = object_world("pour")
    step(model, data, 0.5)
    lid, pitcher = model.body("pour_lid").id, model.body("pour_pitcher").id
    lid0, pitcher0 = data.xpos[lid].copy(), data.xpos[pitcher].copy()
    # Twice its weight, straight up: only the lid's own inertia holds it back.
    data.xfrc_applied[lid, 2] = 2 * model.body_subtreemass[lid] * 9.81
    step(model, data, 0.3)
    assert data.xpos[lid, 2] - lid0[2] > 0.3 * 9.81 * 0.3**2 / 2  # 90% of free rise
    assert np.linalg.norm(data.xpos[pitcher] - pitcher0) < 1e-3


# Light bulb -------------------------------------------------------------------------------


def _twist(
    model: mujoco.MjModel, data: mujoco.MjData, torque: float, seconds: float, speed: float = 1e9
) -> bool:
    """Twist the bulb about +z with ``torque`` (N m) while slower than ``speed`` (rad/s), as
    the physics driver would, updating the thread every step; True once it lets go."""
    (thread,) = find_threads(model)
    bulb = model.body("lightbulb_bulb").id
    for _ in range(round(seconds / model.opt.timestep)):
        data.xfrc_applied[bulb, 5] = torque if abs(data.cvel[bulb, 2]) < speed else 0.0
        mujoco.mj_step(model, data)
        if thread.update(data):
            data.xfrc_applied[bulb] = 0
            return True
    data.xfrc_applied[bulb] = 0
    return False


def test_bulb_rests_and_resists_pulls_and_weak_twists(object_world: ObjectWorld) -> None:
    model, data = object_world("lightbulb")
    bulb, turn = model.body("lightbulb_bulb").id, model.joint("lightbulb_thread_turn").qposadr[0]
    z0 = data.xpos[bulb, 2]
    step(model, data, 1.0)
    assert abs(data.xpos[bulb, 2] - z0) < 3e-4
    data.xfrc_applied[bulb, 2] = 5.0  # a 5 N pull does not unscrew it
    step(model, data, 0.5)
    data.xfrc_applied[bulb] = 0
    assert data.xpos[bulb, 2] - z0 < 1e-3
    assert not _twist(model, data, 0.015, 0.5)  # half the thread's friction: it barely creeps
    assert abs(data.qpos[turn]) < 0.05
    assert not _twist(model, data, -0.1, 0.5)  # clockwise: already tight
    assert data.qpos[turn] > -0.05 and data.xpos[bulb, 2] - z0 > -1e-3


def test_bulb_rises_one_pitch_per_turn_and_comes_free(object_world: ObjectWorld) -> None:
    model, data = object_world("lightbulb")
    bulb = model.body("lightbulb_bulb").id
    turn = model.joint("lightbulb_thread_turn").qposadr[0]
    z0 = data.xpos[bulb, 2]
    (thread,) = find_threads(model)
    assert thread.engaged(data)
    released = False
    for _ in range(200):  # counter-clockwise seen from above, at a hand's pace, in 0.05 s slices
        turns = data.qpos[turn] / (2 * math.pi)
        rise = data.xpos[bulb, 2] - z0
        assert rise == pytest.approx(PITCH * turns, abs=2e-4)
        # The glass turns with the thread.
        x_axis = data.xmat[bulb].reshape(3, 3)[:, 0]
        lag = math.atan2(x_axis[1], x_axis[0]) - data.qpos[turn]
        assert abs(math.remainder(lag, 2 * math.pi)) < 0.01
        if released := _twist(model, data, 0.08, 0.05, speed=3.0):
            break
    assert released and not thread.engaged(data)
    assert data.qpos[turn] / (2 * math.pi) == pytest.approx(TURNS, abs=0.03)
    step(model, data, 0.5)  # loose: it drops back onto the socket floor
    assert data.xpos[bulb, 2] - z0 == pytest.approx(-0.002, abs=1e-3)
    data.xfrc_applied[bulb, 2] = 2 * model.body_subtreemass[bulb] * 9.81
    step(model, data, 0.4)
    assert data.xpos[bulb, 2] - z0 > 0.15  # lifted clear out of the socket
    assert warnings(data) == 0


def test_thread_engages_again_after_reset(object_world: ObjectWorld) -> None:
    model, data = object_world("lightbulb")
    (thread,) = find_threads(model)
    assert thread.name == "lightbulb"
    assert thread.release_turn == pytest.approx(2 * math.pi * TURNS, abs=0.02)
    data.qpos[thread.turn_qpos] = thread.release_turn + 1e-3
    assert thread.update(data) and not thread.update(data)
    mujoco.mj_resetData(model, data)
    assert thread.engaged(data)


def test_a_world_file_sets_the_turns_before_the_thread_lets_go(
    object_world: ObjectWorld, tmp_path: Path
) -> None:
    model, data = object_world("lightbulb")
    set_turns(model, load_world(worlds_dir() / "lightbulb_long.toml"))
    (thread,) = find_threads(model)
    assert thread.release_turn == pytest.approx(2 * math.pi * 3.5, abs=0.02)
    half = write(tmp_path / "half.toml", 'extends = "lightbulb"\n[thread]\nturns = 0.5\n')
    set_turns(model, load_world(half))
    (thread,) = find_threads(model)
    bulb = model.body("lightbulb_bulb").id
    z0 = data.xpos[bulb, 2]
    assert _twist(model, data, 0.08, 2.0, speed=3.0)  # free after half a turn, 2 mm up
    assert data.qpos[thread.turn_qpos] / (2 * math.pi) == pytest.approx(0.5, abs=0.03)
    assert data.xpos[bulb, 2] - z0 == pytest.approx(0.5 * PITCH, abs=3e-4)


def test_thread_turns_need_a_model_with_a_thread(object_world: ObjectWorld) -> None:
    model, _ = object_world("pour")
    set_turns(model, load_world(worlds_dir() / "pour.toml"))  # no [thread]: nothing to do
    world = load_world(worlds_dir() / "lightbulb_long.toml")
    with pytest.raises(WorldFileError, match=r"lightbulb_long.toml: thread: .* no screw thread"):
        set_turns(model, world)


# Resting solids ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("objects", "bodies"),
    [
        ("surface", ["surface_block"]),
        ("containment", ["containment_box", "containment_cylinder", "containment_rounded"]),
        ("pour", ["pour_pitcher", "pour_lid", "pour_cup"]),
    ],
)
def test_solids_rest_stably(object_world: ObjectWorld, objects: str, bodies: list[str]) -> None:
    model, data = object_world(objects)
    ids = [model.body(b).id for b in bodies]
    pos0, z0 = data.xpos[ids].copy(), data.xmat[ids].reshape(-1, 3, 3)[:, :, 2].copy()
    step(model, data, 2.0)
    assert np.abs(data.xpos[ids] - pos0).max() < 1e-3
    z = data.xmat[ids].reshape(-1, 3, 3)[:, :, 2]
    assert np.all(np.einsum("ij,ij->i", z, z0) > math.cos(math.radians(1)))
    assert np.abs(data.cvel[ids]).max() < 0.01
    assert warnings(data) == 0
