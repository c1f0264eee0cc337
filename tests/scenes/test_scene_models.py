"""Every scene compiles with the robot, steps 2 s under noisy control with zero warnings, and
agrees with its world file. These need utah_hand_puma.xml and fail (never skip) without it."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from dial.backend.model import load_model, profile_at
from dial.scene import bundled_scene_names, load_world, worlds_dir
from dial.scene.evaluate import evaluate
from dial.scene.resolve import bundled_world
from dial.scene.thread import find_threads

from ..conftest import ROOT
from .conftest import MODEL_DIR, object_world_xml, warnings

SCENES = ("pour", "lightbulb", "surface", "containment")


def _scene(name: str) -> mujoco.MjModel:
    robot = MODEL_DIR / "utah_hand_puma.xml"
    assert robot.is_file(), f"the robot model {robot} is missing: scenes cannot load"
    return mujoco.MjModel.from_xml_path(str((MODEL_DIR / f"scene_{name}.xml").resolve()))


@pytest.mark.parametrize("name", SCENES)
def test_scene_steps_2s_under_noisy_control_without_warnings(name: str) -> None:
    model = _scene(name)
    data = mujoco.MjData(model)
    threads = find_threads(model)
    rng = np.random.default_rng(0)
    lo, hi = model.actuator_ctrlrange.T
    ctrl = np.clip(np.zeros(model.nu), lo, hi)
    for i in range(round(2.0 / model.opt.timestep)):
        if i % 5 == 0:  # a 100 Hz controller's random walk
            ctrl = np.clip(ctrl + rng.normal(0.0, 0.02 * (hi - lo)), lo, hi)
            data.ctrl[:] = ctrl
        mujoco.mj_step(model, data)
        for thread in threads:
            thread.update(data)
    assert warnings(data) == 0
    assert np.all(np.isfinite(data.qpos))


@pytest.mark.parametrize("name", bundled_scene_names())
def test_world_file_names_exist_in_the_model(name: str) -> None:
    world = load_world(bundled_world(name))
    model = mujoco.MjModel.from_xml_path(str(world.model_path))
    model.site(profile_at(world.robot).arm.tool_site)  # the tool frame of every location
    for body in world.objects.values():
        model.body(body)
    for criterion in world.criteria:
        for attr in ("body", "site", "region"):
            if hasattr(criterion, attr):
                getattr(model, "site" if attr != "body" else "body")(getattr(criterion, attr))
        for prefix in getattr(criterion, "fingers", ()):
            assert any(model.body(i).name.startswith(prefix) for i in range(model.nbody)), prefix


def test_criteria_at_the_start_of_each_task() -> None:
    expected = {
        "pour": {"contents_in_cup": False, "pitcher_upright": True},
        "lightbulb": {"bulb_out": False, "bulb_held": False},
        "surface": {"top_plane": False},  # nothing fitted yet
        "containment": {"shape_fit": False},
    }
    for name, success in expected.items():
        world = load_world(worlds_dir() / f"{name}.toml")
        model = mujoco.MjModel.from_xml_path(str(world.model_path))
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        assert evaluate(world.criteria, model, data, {}) == success


def test_object_worlds_use_the_robot_physics_options() -> None:
    scene = _scene("surface")
    objects = mujoco.MjModel.from_xml_string(object_world_xml("surface"))
    for field in ("timestep", "integrator", "cone", "impratio", "solver", "iterations"):
        assert getattr(objects.opt, field) == getattr(scene.opt, field), field


def test_the_pour_scene_before_issue_16_still_loads() -> None:
    """benchmarks/bench_engine.py compares the pour physics with this copy of the old scene."""
    world = load_world(ROOT / "benchmarks" / "pour_before" / "pour_before.toml")
    model = load_model(world.model_path)
    balls = [b for b in range(model.nbody) if model.body(b).name.startswith("pour_ball_")]
    assert len(balls) == 36
    assert not model.opt.enableflags & mujoco.mjtEnableBit.mjENBL_SLEEP
    assert set(world.programs) == set(load_world(worlds_dir() / "pour.toml").programs)
