"""The preview's IK (``dial.preview.ik``) against the run's: the same answers, to rounding."""

from __future__ import annotations

import itertools
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from dial.api import load
from dial.backend.ik import ArmIK, FingerIK, IKError
from dial.backend.model import ARM_HOME, ROBOT_DIR, load_model, load_untextured
from dial.geometry import Slerp, rpy_matrix
from dial.preview import preview
from dial.preview.ik import FingerIKOnDemand, LeanArmIK, box_qp
from dial.primitives.arm import Planner
from dial.robot.memo import forget_solutions
from dial.robot.snapshot import FloatArray


@pytest.fixture(scope="module")
def solvers() -> tuple[ArmIK, LeanArmIK]:
    return ArmIK(), LeanArmIK()


def test_a_line_is_tracked_as_the_run_tracks_it(solvers: tuple[ArmIK, LeanArmIK]) -> None:
    run, lean = solvers
    q0 = np.array(ARM_HOME)
    p0, r0 = run.fk(q0)
    p1, r1 = p0 + np.array([0.1, -0.15, 0.2]), r0 @ rpy_matrix((0.3, -0.2, 0.5))
    turning = Slerp(r0, r1)
    a, b = [q0], [q0]
    for k in range(1, 100):  # 2.7 mm apart, as a line's waypoints are
        goal = p0 + (p1 - p0) * k / 100, turning(k / 100)
        a.append(run.track(*goal, a[-1]))
        b.append(lean.track(*goal, b[-1]))
    assert np.abs(np.array(a) - np.array(b)).max() < 1e-9
    assert np.abs(np.array(a[1:]) - q0).max() > 0.1  # it did move


def test_targets_are_solved_as_the_run_solves_them(solvers: tuple[ArmIK, LeanArmIK]) -> None:
    run, lean = solvers
    rng = np.random.default_rng(0)
    home = np.array(ARM_HOME)
    for _ in range(12):
        start = home + rng.normal(0.0, 0.5, 6)
        pos, rot = run.fk(home + rng.normal(0.0, 0.7, 6))
        try:
            expected = run.solve(pos, rot, start, "x")
        except IKError as e:  # out of reach from there: the preview says the same
            with pytest.raises(IKError, match=re.escape(str(e))):
                lean.solve(pos, rot, start, "x")
            continue
        assert np.abs(expected - lean.solve(pos, rot, start, "x")).max() < 1e-9


def test_a_target_out_of_reach_fails_with_the_runs_figures(
    solvers: tuple[ArmIK, LeanArmIK],
) -> None:
    run, lean = solvers
    home = np.array(ARM_HOME)
    pos, rot = run.fk(home)
    far = pos + np.array([1.9, 0.0, 0.0])
    messages = []
    for ik in (run, lean):
        with pytest.raises(IKError) as e:
            ik.solve(far, rot, home, "the far target")
        messages.append(str(e.value))
    assert messages[0] == messages[1]
    assert "out of the arm's reach" in messages[0]


def test_the_runs_memo_never_serves_the_previews_answers(
    solvers: tuple[ArmIK, LeanArmIK],
) -> None:
    run, lean = solvers
    home = np.array(ARM_HOME)
    pos, rot = run.fk(home + 0.05)

    def line(ik: ArmIK) -> FloatArray:
        planner = Planner(SimpleNamespace(arm_ik=ik), home)  # type: ignore[arg-type]
        planner.line_to(pos, rot, "a line")
        return planner.segments[-1].waypoints

    forget_solutions()
    fresh = run.solve(pos, rot, home, "x"), line(run)
    forget_solutions()
    lean.solve(pos, rot, home, "x"), line(lean)  # what a preview leaves in the memo
    assert run.solve(pos, rot, home, "x").tobytes() == fresh[0].tobytes()
    assert line(run).tobytes() == fresh[1].tobytes()


def test_box_qp_satisfies_the_optimality_conditions() -> None:
    rng = np.random.default_rng(1)
    for _ in range(200):
        m = rng.normal(size=(6, 6))
        hessian = m.T @ m + 1e-3 * np.eye(6)
        b = rng.normal(size=6) * 3
        low, high = -rng.uniform(0.0, 1.0, 6), rng.uniform(0.0, 1.0, 6)
        x = box_qp(hessian, b, low, high)
        assert np.all(x >= low - 1e-12) and np.all(x <= high + 1e-12)
        force = hessian @ x - b  # zero where free, pushing outward where held at a bound
        free = (x > low + 1e-9) & (x < high - 1e-9)
        assert np.abs(force[free]).max(initial=0.0) < 1e-9
        assert np.all(force[np.isclose(x, low)] >= -1e-9)
        assert np.all(force[np.isclose(x, high)] <= 1e-9)
        # no better feasible point among the corners and the clipped unconstrained optimum
        best = 0.5 * x @ hessian @ x - b @ x
        for corner in itertools.product(*zip(low, high, strict=True)):
            c = np.array(corner)
            assert 0.5 * c @ hessian @ c - b @ c >= best - 1e-9


def test_a_scene_compiled_without_textures_has_the_same_geometry() -> None:
    path = ROBOT_DIR / "scene_pour.xml"
    full, bare = load_model(path), load_untextured(path)
    assert bare.ntex == 0 < full.ntex
    for field in ("body_pos", "body_quat", "body_mass", "geom_size", "geom_pos", "geom_quat"):
        assert np.array_equal(getattr(full, field), getattr(bare, field)), field
    for field in ("geom_type", "geom_contype", "geom_conaffinity", "jnt_range", "qpos0"):
        assert np.array_equal(getattr(full, field), getattr(bare, field)), field


def test_the_fingers_ik_set_up_on_first_use_answers_as_the_runs() -> None:
    run, later = FingerIK(), FingerIKOnDemand(load_model())
    arm, hand = np.array(ARM_HOME), np.zeros(16)
    tip = run.tip(arm, hand, 0)
    assert later.tip(arm, hand, 0).tobytes() == tip.tobytes()
    goal = tip + np.array([0.0, 0.0, 0.005])
    forget_solutions()
    expected = run.track(0, goal, arm, hand)
    forget_solutions()
    assert later.track(0, goal, arm, hand).tobytes() == expected.tobytes()
    assert np.abs(expected - hand).max() > 0.0  # the finger moved


def test_a_finger_move_is_previewed(tmp_path: Path) -> None:
    script = tmp_path / "tap.dial"
    script.write_text("@scene surface\n% tap finger_move finger=index 5mm 0 0\n\ntap #==\n")
    result = preview(load(script))
    # ok: the fingertip ended within 3 mm of its goal, 5 mm away (the fingers' IK moved it)
    assert result.ok and result.counts.hand == 1, result.problems
