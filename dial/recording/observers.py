"""The rerun recorder, an observer of a run (see :class:`dial.engine.Observer`).

They sample on whole numbers of control periods, so a frame's time is exact simulated time
and the same run gives the same frames.
"""

from __future__ import annotations

import mujoco

from dial.engine import RunResult, Watched
from dial.recording.frames import RECORD_HZ, Frames, every
from dial.recording.geometry import task_camera
from dial.recording.rerun_sink import RerunSink


def object_bodies(model: mujoco.MjModel, bodies: list[str]) -> list[int]:
    return [int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b)) for b in bodies]


class Recorder:
    """Records a run into a :class:`RerunSink`: frames at ``rate_hz``, every log record."""

    def __init__(self, sink: RerunSink, title: str, rate_hz: float = RECORD_HZ) -> None:
        self.sink, self.title, self.rate_hz = sink, title, rate_hz
        self._seen = 0  # log records already sent
        self._tick = 0

    def begin(self, run: Watched) -> None:
        self.robot, self.log = run.robot, run.log
        model, data = run.robot.model, run.robot.data
        self.frames = Frames(model)
        self.every = every(self.rate_hz, run.robot.period)
        camera = task_camera(data, object_bodies(model, list(run.world.objects.values())))
        self.sink.scene(model, data, self.title, camera)
        self._capture(0, 0)

    def period(self, periods: int, tick: int) -> None:
        if periods % self.every == 0:
            self._capture(periods, tick)

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
