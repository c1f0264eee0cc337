"""Straight arm lines (MOVES, DEPART, arm_move): waypoints solved at the start, on the line."""

from __future__ import annotations

from types import SimpleNamespace
from typing import cast

import numpy as np
import pytest

from dial.backend.ik import ArmIK
from dial.backend.model import ARM_HOME, profile_at
from dial.geometry import rpy_matrix, slerp
from dial.primitives.arm import LINE_STEP, Planner
from dial.primitives.context import Context

from ..conftest import ROOT


@pytest.fixture(scope="module")
def ik() -> ArmIK:
    return ArmIK()


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.arccos(np.clip((np.trace(a.T @ b) - 1.0) / 2.0, -1.0, 1.0)))


def test_the_tool_stays_on_the_line_between_waypoints(ik: ArmIK) -> None:
    q0 = ik.solve(np.array([0.5, 0.0, 0.7]), rpy_matrix((np.pi, 0, 0)), np.array(ARM_HOME), "x")
    planner = Planner(cast(Context, SimpleNamespace(arm_ik=ik)), q0)
    p0, r0 = ik.fk(q0)
    p1, r1 = p0 + np.array([0.10, 0.06, -0.12]), rpy_matrix((0, 0, np.radians(30))) @ r0
    planner.line_to(p1, r1, "the goal")
    (seg,) = planner.segments
    length = float(np.linalg.norm(p1 - p0))
    assert len(seg.waypoints) - 1 == int(np.ceil(length / LINE_STEP))  # 0.17 m: 43 steps
    assert np.array_equal(seg.at(0.0), q0) and np.array_equal(seg.at(1.0), seg.q1)
    worst_pos = worst_rot = 0.0
    for u in np.linspace(0.0, 1.0, 401):  # between the waypoints too
        pos, rot = ik.fk(seg.at(float(u)))
        worst_pos = max(worst_pos, float(np.linalg.norm(pos - (p0 + (p1 - p0) * u))))
        worst_rot = max(worst_rot, _angle(rot, slerp(r0, r1, float(u))))
    assert worst_pos < 0.2e-3  # m (measured 0.05 mm; the ends alone would be cm off)
    assert worst_rot < np.radians(0.1)


def test_a_redundant_arms_line_ends_in_the_arm_posture_it_tracked() -> None:
    # allegro_panda's 7-joint arm coming down 100 mm beside containment's rounded solid (the
    # first side touch of a trial at 10 mm, seed 2680900435): its goal, solved from afar,
    # holds the elbow 50 deg from where the line starts, and the line's last step swung
    # joints 1 and 3 that far. Drawn to the joints' interpolation, the waypoints move the
    # elbow evenly, a few degrees a step, and stay within a millimetre of the line.
    profile = profile_at(ROOT / "models" / "allegro_panda")
    ik = ArmIK(profile=profile)
    rot = rpy_matrix(np.radians((167.0, 0.0, -90.0)))
    above, down = np.array([0.4263, -0.1976, 0.6303]), np.array([0.4263, -0.1976, 0.5303])
    start = np.array([1.042, -0.1777, -1.3955, -2.1886, -0.2654, 1.9269, 2.1461])
    planner = Planner(cast(Context, SimpleNamespace(arm_ik=ik)), ik.solve(above, rot, start, "x"))
    planner.line_to(down, rot, "the goal")
    (seg,) = planner.segments
    steps = np.abs(np.diff(seg.waypoints, axis=0)).max(axis=1)
    assert np.degrees(steps.max()) < 5.0, np.degrees(steps).round(1)
    worst_pos = worst_rot = 0.0
    for u in np.linspace(0.0, 1.0, 201):
        pos, turned = ik.fk(seg.at(float(u)))
        worst_pos = max(worst_pos, float(np.linalg.norm(pos - (above + (down - above) * u))))
        worst_rot = max(worst_rot, _angle(turned, rot))
    assert worst_pos < 1.5e-3 and worst_rot < np.radians(0.5)  # measured 0.84 mm, 0.28 deg
