"""Which fingers touch an object (the world model's question while the hand holds something):
:class:`dial.backend.locate.FingerContacts` keeps the fingers' links as bit masks; it counts
what the plain definition counts, on every bundled scene, with each free object pushed into
each fingertip in turn."""

from __future__ import annotations

import mujoco
import pytest

from dial.backend.index import RobotIndex
from dial.backend.locate import FingerContacts
from dial.backend.model import finger_bodies, load_model, profile_at
from dial.scene.resolve import bundled_scene_names, resolve_scene, worlds_dir
from dial.scene.world import load_world


def _definition(
    model: mujoco.MjModel, data: mujoco.MjData, body: int, links: list[tuple[int, ...]]
) -> list[int]:
    """The fingers with a link in contact with ``body``, from the contacts one by one."""
    touching = set()
    for c in data.contact[: data.ncon]:
        pair = (int(model.geom_bodyid[c.geom1]), int(model.geom_bodyid[c.geom2]))
        if body in pair:
            other = pair[1] if pair[0] == body else pair[0]
            touching |= {f for f, bodies in enumerate(links) if other in bodies}
    return sorted(touching)


@pytest.mark.parametrize("scene", bundled_scene_names())
def test_counts_match_the_definition(scene: str) -> None:
    world = load_world(resolve_scene(scene, worlds_dir()))
    profile = profile_at(world.robot)
    model = load_model(world.model_path, profile, textures=False)
    data = mujoco.MjData(model)
    index = RobotIndex.from_model(model, profile)
    links = [finger_bodies(model, f.joints) for f in profile.fingers]
    contacts = FingerContacts(model, data, links)
    every = tuple(range(len(links)))
    touched = moved = 0
    for name in world.objects.values():
        body = model.body(name)
        if body.jntnum[0] == 0 or model.jnt_type[body.jntadr[0]] != mujoco.mjtJoint.mjJNT_FREE:
            continue  # fixed to the world: it cannot be moved into a fingertip
        adr = int(model.jnt_qposadr[body.jntadr[0]])
        for f, site in enumerate(index.fingertip_sites):
            mujoco.mj_forward(model, data)
            data.qpos[adr : adr + 3] = data.site_xpos[site]
            mujoco.mj_forward(model, data)
            expected = _definition(model, data, body.id, links)
            assert contacts.count(name, every) == len(expected), (scene, name, f)
            for one in every:
                assert contacts.count(name, (one,)) == int(one in expected)
            touched += bool(expected)
            moved += 1
    assert touched == moved  # each object pushed into a fingertip touches a finger
