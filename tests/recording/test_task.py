"""The task's measurements over a run: the scene criteria's own readings (task.py)."""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest

from dial.backend.model import load_model
from dial.recording.task import Series, TaskProbe
from dial.scene.evaluate import measure
from dial.scene.resolve import resolve_scene
from dial.scene.world import load_world


def _scene(name: str) -> tuple[TaskProbe, mujoco.MjModel, mujoco.MjData, list[str]]:
    world = load_world(resolve_scene(name, Path(".")))
    model = load_model(world.model_path)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    texts = [measure(c, model, data, {})[1] for c in world.criteria]
    return TaskProbe(model, world.criteria, world.objects), model, data, texts


def test_the_light_bulb_plots_its_height_its_grip_and_its_turn() -> None:
    probe, model, data, texts = _scene("lightbulb")
    assert probe.series == [
        Series("bulb_out", "bulb height", "mm"),
        Series("bulb_held", "bulb touch", "fingers"),
        Series("lightbulb_turn", "lightbulb turn", "deg"),
    ]
    height, fingers, turn = probe.sample(data)
    assert texts[0] == f"{height:.1f} mm above lightbulb_socket_top"  # the verdict's number
    assert (fingers, turn) == (0.0, 0.0)
    data.qpos[model.joint("lightbulb_thread_turn").qposadr[0]] = 0.5
    mujoco.mj_forward(model, data)
    assert probe.sample(data)[2] == pytest.approx(28.6479, abs=1e-3)  # 0.5 rad


def test_pour_plots_the_cup_contents_and_the_pitcher_tilt() -> None:
    probe, _, data, texts = _scene("pour")
    assert [s.label for s in probe.series] == ["cup contents", "pitcher tilt"]
    inside, tilt = probe.sample(data)
    assert texts == [f"{inside:.0f}/20 in pour_cup_inside (min 50%)", f"tilt {tilt:.1f} deg"]


def test_criteria_that_judge_a_fit_are_not_plotted() -> None:
    probe, _, data, _ = _scene("surface")
    assert probe.series == [] and probe.sample(data).shape == (0,)
