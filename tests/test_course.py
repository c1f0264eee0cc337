"""A course writes, bit for bit, the set-points that stepping writes (``Primitive.course``).

Coasting takes an open-loop run's set-points for many periods at once; the runner, the
preview and these tests compute its progress with the one ``progress_after``. For random
plans, spans, tick lengths and ways of cutting the run's periods into courses, the arm's and
the hand's set-points after every period are those of stepping through the same periods.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

pytest.importorskip(
    "hypothesis", reason="the 'test' extra is not installed: pip install -e '.[test]'"
)
from hypothesis import given, settings
from hypothesis import strategies as st

from dial.primitives.arm import ArmMotion, Planner, Segment
from dial.primitives.hand import HandPose
from dial.scheduler.primitive import Allotment, Now, Primitive, progress_after


class _Robot:
    """What the slots write: the set-points."""

    def __init__(self) -> None:
        self.arm_target = np.zeros(6)
        self.hand_target = np.zeros(16)


class _Planned(ArmMotion):
    """An arm motion along given segments (no IK)."""

    def __init__(self, ctx: Any, allotted: Allotment, segments: list[Segment]) -> None:
        super().__init__(ctx, allotted)
        self.planned = segments

    def plan(self, planner: Planner) -> None:
        planner.segments += self.planned


@st.composite
def _shape(draw: st.DrawFn) -> tuple[int, int, list[int]]:
    """Periods per tick, the run's span in periods, and a cut of its periods into courses."""
    n = draw(st.integers(1, 25))
    span = n * draw(st.integers(1, 6))
    cuts = sorted(set(draw(st.lists(st.integers(1, span - 1), max_size=6)))) if span > 1 else []
    return n, span, [b - a for a, b in zip([0, *cuts], [*cuts, span], strict=True)]


@st.composite
def _segments(draw: st.DrawFn) -> list[Segment]:
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    out = []
    for _ in range(draw(st.integers(1, 4))):
        rows = draw(st.sampled_from([2, 2, 3, 17]))
        waypoints = rng.uniform(-2.0, 2.0, (rows, 6))
        out.append(Segment(waypoints, float(draw(st.sampled_from([0.0, 0.3, 1.0, 2.5])))))
    return out


def _stepped(prim: Primitive[Any], robot: _Robot, n: int, span: int) -> list[bytes]:
    """The set-points after each period of stepping."""
    out = []
    for k in range(1, span + 1):
        prim.step(None, Now(0.0, 1, progress_after(k, span, n), 0.0, False))
        out.append(robot.arm_target.tobytes() + robot.hand_target.tobytes())
    return out


def _coasted(prim: Primitive[Any], robot: _Robot, cuts: list[int]) -> list[bytes]:
    """The set-points after each period, coasting through courses of ``cuts`` periods."""
    out, first = [], 1
    for count in cuts:
        write = prim.course(first, count)
        for j in range(count):
            write(j)
            out.append(robot.arm_target.tobytes() + robot.hand_target.tobytes())
        first += count
    return out


def _both(make: Any, shape: tuple[int, int, list[int]]) -> tuple[list[bytes], list[bytes]]:
    n, span, cuts = shape
    runs = []
    for _ in range(2):
        robot = _Robot()
        prim = make(SimpleNamespace(robot=robot), robot, span, n)
        prim.start(SimpleNamespace(arm_target=robot.arm_target, hand_target=robot.hand_target))
        runs.append((prim, robot))
    return _stepped(*runs[0], n, span), _coasted(*runs[1], cuts)


@settings(max_examples=150, deadline=None)
@given(_shape(), _segments())
def test_an_arm_motions_course_is_its_steps(
    shape: tuple[int, int, list[int]], segments: list[Segment]
) -> None:
    def make(ctx: Any, robot: _Robot, span: int, n: int) -> ArmMotion:
        return _Planned(ctx, Allotment(frozenset({"arm"}), span, n, 0.01), segments)

    stepped, coasted = _both(make, shape)
    assert coasted == stepped


@settings(max_examples=150, deadline=None)
@given(_shape(), st.integers(1, 0xFFFF), st.integers(0, 2**32 - 1))
def test_a_hand_poses_course_is_its_steps(
    shape: tuple[int, int, list[int]], mask: int, seed: int
) -> None:
    rng = np.random.default_rng(seed)
    angles = {k: float(a) for k, a in enumerate(rng.uniform(-0.3, 1.5, 16))}
    start = rng.uniform(-0.3, 1.5, 16)
    world = SimpleNamespace(poses={"p": SimpleNamespace(mask=mask, angles=angles)})
    fingers = frozenset({"index", "middle", "ring", "thumb"})

    def make(ctx: Any, robot: _Robot, span: int, n: int) -> HandPose:
        ctx.world = world
        robot.hand_target = start.copy()
        return HandPose(ctx, Allotment(fingers, span, n, 0.01), "p", 0xFFFF)

    stepped, coasted = _both(make, shape)
    assert coasted == stepped


def test_progress_is_a_goto_for_a_one_tick_run_and_linear_otherwise() -> None:
    assert [progress_after(k, 10, 10) for k in (0, 1, 10)] == [1.0, 1.0, 1.0]
    assert [progress_after(k, 40, 10) for k in (0, 10, 40, 41)] == [0.0, 0.25, 1.0, 1.0]
