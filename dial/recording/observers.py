"""The rerun recorder, an observer of a run (see :class:`dial.engine.Observer`).

They sample on whole numbers of control periods, so a frame's time is exact simulated time
and the same run gives the same frames.
"""

from __future__ import annotations

import mujoco

from dial.backend.model import profile_at
from dial.engine import RunResult, Watched
from dial.engine.observe import every
from dial.parser.lanes import LanePlan
from dial.recording.frames import RECORD_HZ, Frames
from dial.recording.geometry import workspace_eye
from dial.recording.rerun_sink import RerunSink
from dial.recording.task import TaskProbe
from dial.scene.world import World


def object_bodies(model: mujoco.MjModel, bodies: list[str]) -> list[int]:
    return [int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b)) for b in bodies]


def open_scene(
    sink: RerunSink,
    model: mujoco.MjModel,
    data: mujoco.MjData,
    world: World,
    title: str,
    plan: LanePlan | None,
) -> Frames:
    """Send the scene and the layout to ``sink``; the frames to fill, with the task's probe."""
    probe = TaskProbe(model, world.criteria, world.objects)
    eye = workspace_eye(data, object_bodies(model, list(world.objects.values())))
    profile = profile_at(world.robot)
    sink.scene(model, data, title, eye, world.objects, probe.series, plan, profile)
    return Frames(model, probe, profile)


class Recorder:
    """Records a run into a :class:`RerunSink`: frames at ``rate_hz``, every log record.

    ``plan`` (the script's lanes, :meth:`LanePlan.from_script`) orders the event lanes as in
    the script and draws holds; without it lanes come in the order events first run.
    """

    what = "the rerun recording"  # how messages name it

    def __init__(
        self,
        sink: RerunSink,
        title: str,
        rate_hz: float = RECORD_HZ,
        plan: LanePlan | None = None,
    ) -> None:
        self.sink, self.title, self.rate_hz, self.plan = sink, title, rate_hz, plan
        self._seen = 0  # log records already sent
        self._tick = 0
        self._now = (0, 0)  # (periods, tick) of the last period

    def begin(self, run: Watched) -> None:
        self.robot, self.log = run.robot, run.log
        model, data = run.robot.model, run.robot.data
        self.frames = open_scene(self.sink, model, data, run.world, self.title, self.plan)
        self.every = every(self.rate_hz, run.robot.period)
        self._capture(0, 0)

    def period(self, periods: int, tick: int) -> None:
        self._now = (periods, tick)
        if periods % self.every == 0:
            self._capture(periods, tick)

    def show_now(self) -> None:
        """A paused run: record this moment (unless it was just recorded) and send it."""
        periods, tick = self._now
        if periods % self.every:
            self._capture(periods, tick)
        self._drain()
        self._send()

    def _capture(self, periods: int, tick: int) -> None:
        self._tick = tick
        self._drain()
        self.frames.capture(periods * self.robot.period, tick, self.robot.data)
        if len(self.frames) >= self.sink.batch:
            self._send()

    def _drain(self) -> None:
        records = self.log.records
        if self._seen == len(records):
            return
        tips = self.robot.data.site_xpos[self.robot.index.fingertip_sites]
        for record in records[self._seen :]:
            self.sink.record(record, self._tick, tips)
        self._seen = len(records)

    def _send(self) -> None:
        batch = self.frames.take()
        if batch is not None:
            self.sink.frames(batch)

    def end(self, result: RunResult | None) -> None:
        self._drain()  # the log's last record is the engine's summary
        self._send()
        self.sink.close()
