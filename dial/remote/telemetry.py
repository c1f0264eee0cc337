"""The robot's settings and its telemetry: its state every few control periods, for the
operator's progress and prediction (decimated to fit the link's bandwidth)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from dial.backend.driver import MujocoRobot
from dial.disturb import Disturbance, parse_disturbance
from dial.engine.observe import Watched
from dial.engine.result import RunResult
from dial.remote.protocol import encode
from dial.remote.session import Session

SAMPLE_BYTES = 420  # about the size of one telemetry message
TELEMETRY_EVERY = 10  # control periods between samples at most (0.1 s of simulated time)


@dataclass(frozen=True)
class RobotConfig:
    """The robot's own settings (``dial serve``'s options)."""

    scene: str | None
    perturb: float
    seed: int
    disturb: tuple[str, ...]
    pace: float
    watchdog: float


class Telemetry:
    """An observer: the robot's state every few control periods, as a telemetry sample."""

    what = "telemetry"

    def __init__(self, session: Session, every: int) -> None:
        self.session, self.every = session, every
        self.robot: MujocoRobot | None = None

    def begin(self, run: Watched) -> None:
        self.robot = run.robot

    def period(self, periods: int, tick: int) -> None:
        if periods % self.every == 0:
            self.sample(periods, tick)

    def end(self, result: RunResult | None) -> None:
        pass

    def sample(self, periods: int, tick: int) -> None:
        robot = self.robot
        assert robot is not None
        d, ix = robot.data, robot.index
        tool = [round(float(x) * 1000.0, 2) for x in d.site_xpos[ix.tool_site]]
        arm = [round(float(x), 5) for x in d.qpos[ix.arm_qpos]]
        hand = [round(float(x), 5) for x in d.qpos[ix.hand_qpos]]
        t = round(periods * robot.period, 6)
        block, since = self.session.block
        fields: dict[str, object] = {"tick": tick, "t": t, "tool": tool, "arm": arm, "hand": hand}
        fields.update(block=block, since=periods - since)
        self.session.sample(encode("telemetry", periods=periods, **fields), fields)


def telemetry_every(period: float, pace: float, bandwidth: float | None) -> int:
    """Control periods between telemetry samples: at most half the link's bandwidth."""
    if bandwidth is None:
        return TELEMETRY_EVERY
    wall = 2.0 * SAMPLE_BYTES * 8.0 / bandwidth  # s of wall time between samples, at least
    return max(TELEMETRY_EVERY, math.ceil(wall / (period * pace)))


def disturbances(texts: Sequence[str]) -> list[Disturbance]:

    return [parse_disturbance(t) for t in texts]
