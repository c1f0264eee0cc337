"""Engine-owned safety monitors on the MuJoCo driver."""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest

from dial.backend.driver import MujocoRobot
from dial.backend.model import load_model
from dial.scene import models_dir


def _robot() -> MujocoRobot:
    model = load_model(models_dir() / "utah_hand_puma" / "scene_surface.xml")
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return MujocoRobot(model, data)


def test_a_diverging_state_is_a_fault(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)  # MuJoCo writes its warning to MUJOCO_LOG.TXT here
    robot = _robot()
    assert robot.advance() is None
    robot.data.qvel[robot.index.hand_dof[0]] = 1e12  # beyond MuJoCo's bound: it resets
    report = robot.advance()
    assert report is not None
    assert report.fault == "the physics diverged (MuJoCo reset an unstable state)"


def test_an_arm_joint_past_its_limit_is_a_fault() -> None:
    robot = _robot()
    j = robot.index.arm_qpos[1]
    robot.data.qpos[j] = robot.model.jnt_range[1, 1] + 0.2  # joint 2, far past its stop
    robot.arm_target = robot.data.qpos[robot.index.arm_qpos].copy()
    report = robot.advance()
    assert report is not None and report.fault is not None
    assert report.fault.startswith("PUMA joint 2 is beyond its limit")


def test_a_tendon_held_at_its_limit_is_logged_once_per_episode() -> None:
    robot = _robot()
    robot.arm_target = robot.data.qpos[robot.index.arm_qpos].copy()
    robot.safety._pinned_at = 5.0  # below the 10 N pretension: every tendon counts as pinned
    for _ in range(99):  # 0.99 s: not yet held for a second
        assert robot.advance() is None
    warnings = []
    for _ in range(100):  # a run never aborts for it
        report = robot.advance()
        assert report is None or report.fault is None
        warnings += [h for h in (report.happenings if report else ()) if h.kind == "warning"]
    assert len(warnings) == 32  # each tendon once, not once per period
    message = warnings[0].fields["message"]
    assert "index joint 0 flexor tendon held at its 50 N limit for 1 s" in str(message)


def test_restored_tendon_timers_go_on_as_the_run_that_saved_them() -> None:
    """A state file's tendon timers: a resumed robot reports what the saving one goes on to
    report, also when a tendon was logged as pinned before the save and lets go after it."""
    saving, resumed = _robot(), _robot()
    for robot in (saving, resumed):
        robot.arm_target = robot.data.qpos[robot.index.arm_qpos].copy()
        robot.safety._pinned_at = 5.0  # below the 10 N pretension: every tendon is pinned
    for _ in range(150):  # 1.5 s: each tendon logged once
        saving.advance()
    assert saving.safety.saturation_logged.all()
    saving.safety._pinned_at = resumed.safety._pinned_at = 1e9  # nothing is pinned from now
    state = mujoco.MjData(saving.model)
    mujoco.mj_copyData(state, saving.model, saving.data)
    mujoco.mj_copyData(resumed.data, resumed.model, state)
    resumed.steps = saving.steps
    resumed.safety.restore(saving.safety.saturated_since, saving.safety.saturation_logged)
    for _ in range(3):
        assert resumed.advance() == saving.advance()
        assert (resumed.safety.saturation_logged == saving.safety.saturation_logged).all()
        assert (resumed.safety.saturated_since == saving.safety.saturated_since).all()
    assert not saving.safety.saturation_logged.any()  # let go: the episode ended
