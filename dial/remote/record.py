"""``dial run --remote --record/--rerun``: the predicted robot and the reported one together.

The prediction's run is recorded as a local run is (its robot, tactile images, plots, lanes
and log, under the usual entity paths). The reported robot is drawn beside it in the same
recording: its arm and hand under ``world/reported`` (the scene's model posed with the
joint angles of each telemetry sample, in one translucent colour), and its event lanes,
from the robot's reported records, under ``reported``. ``diverged`` records go into the
text log. Both robots are on the same ``sim_time`` and ``tick`` timelines, each on its own
clock (a ``--split block`` robot that waits between blocks falls behind its prediction).

**One writer.** rerun's recording stream takes data from any thread, but it orders data
only per thread, and a flush waits only for what the flushing thread sent; a stream written
from two threads and closed from one may lose the other's last data. So only the
prediction's thread writes: the operator's thread puts what the robot reports into
:attr:`RemoteRecorder.inbox`, the recorder draws it between its own frames, and when the
predicted run has ended it goes on drawing reports until the operator says the remote run
is over (:meth:`RemoteRecorder.over`); then it closes the recording.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Mapping
from pathlib import Path

import mujoco
import numpy as np

from dial.engine.observe import Watched
from dial.engine.result import RunResult
from dial.parser.lanes import LanePlan
from dial.parser.script import Script
from dial.recording.geometry import body_paths, moving_bodies
from dial.recording.lanes import Lanes
from dial.recording.observers import Recorder
from dial.recording.rerun_sink import RerunSink
from dial.scheduler.log import Record

REPORTED = "reported"  # the reported robot's entity paths: world/reported/..., reported/...
GHOST_RGBA = np.array([0.3, 0.75, 1.0, 0.45])  # how the reported robot is drawn
Item = tuple[str, Mapping[str, object]]  # ("sample" | "record" | "diverged", its fields)


class ReportedRobot:
    """The reported robot in the recording: a pose of the scene's model per telemetry
    sample, and lanes from its records (drawn by the prediction's thread only)."""

    def __init__(self, sink: RerunSink, run: Watched, plan: LanePlan | None) -> None:
        model = run.robot.model
        self.sink, self.index = sink, run.robot.index
        self.data = mujoco.MjData(model)  # its own: the prediction's state is not touched
        self.model = model
        paths = body_paths(model, run.world.objects)
        robot = [int(b) for b in moving_bodies(model) if paths[b].startswith(("arm/", "hand/"))]
        self.paths = {b: f"world/{REPORTED}/{paths[b]}" for b in robot}
        sink.ghost(model, self.paths, GHOST_RGBA)
        self.lanes = Lanes(plan)
        sink.open_lanes(self.lanes, (REPORTED,))
        self.t, self.tick = 0.0, 0  # the latest sample's
        ix, start = self.index, run.robot.data  # until the first sample: where both start
        self.sample(
            {
                "t": 0.0,
                "tick": 0,
                "arm": list(start.qpos[ix.arm_qpos]),
                "hand": list(start.qpos[ix.hand_qpos]),
            }
        )

    def sample(self, fields: Mapping[str, object]) -> None:
        arm, hand = _numbers(fields.get("arm")), _numbers(fields.get("hand"))
        t, tick = fields.get("t"), fields.get("tick")
        ix = self.index
        if len(arm) != len(ix.arm_qpos) or len(hand) != len(ix.hand_qpos):
            return
        if not isinstance(t, int | float) or not isinstance(tick, int):
            return
        self.t, self.tick = float(t), tick
        self.data.qpos[ix.arm_qpos] = arm
        self.data.qpos[ix.hand_qpos] = hand
        mujoco.mj_kinematics(self.model, self.data)
        self.sink.poses(self.t, tick, self.paths, self.data)
        self.sink.phases(self.lanes.flush(self.t), (REPORTED,))

    def record(self, record: Mapping[str, object]) -> None:
        if isinstance(record.get("kind"), str):
            self.sink.phases(self.lanes.feed(record), (REPORTED,))

    def diverged(self, fields: Mapping[str, object]) -> None:
        what, event, tick = fields.get("what"), fields.get("event"), fields.get("tick")
        if what == "tool":
            detail = f"the tool {fields.get('distance_mm')} mm from the prediction"
        else:
            detail = f"{what} {fields.get('reported')}, predicted {fields.get('predicted')}"
        t = fields.get("t")
        at = float(t) if isinstance(t, int | float) else self.t
        k = tick if isinstance(tick, int) else self.tick
        self.sink.line(at, k, f"diverged at tick {tick} ({event or 'no event'}): {detail}", "warn")

    def close(self) -> None:
        self.sink.phases(self.lanes.flush(), (REPORTED,))


def _numbers(value: object) -> list[float]:
    if not isinstance(value, list):
        return []
    return [float(x) for x in value if isinstance(x, int | float) and not isinstance(x, bool)]


class RemoteRecorder(Recorder):
    """The prediction's recorder, which also draws the reported robot (see the module)."""

    def __init__(self, sink: RerunSink, script: Script) -> None:
        plan = LanePlan.from_script(script)
        super().__init__(sink, Path(script.path).name, plan=plan)
        self.inbox: queue.SimpleQueue[Item | None] = queue.SimpleQueue()
        self.closed = threading.Event()  # the recording is complete and closed
        self.reported: ReportedRobot | None = None
        self._over = False

    # -- the operator's thread: what the robot reports, queued ---------------------------------
    def sample(self, fields: Mapping[str, object]) -> None:
        self.inbox.put(("sample", dict(fields)))

    def record(self, record: Record) -> None:
        self.inbox.put(("record", record))

    def diverged(self, fields: Mapping[str, object]) -> None:
        self.inbox.put(("diverged", dict(fields)))

    def over(self) -> None:
        """The remote run is over: nothing more will be reported."""
        self.inbox.put(None)

    # -- the prediction's thread: the only writer -------------------------------------------------
    def begin(self, run: Watched) -> None:
        super().begin(run)
        self.reported = ReportedRobot(self.sink, run, self.plan)

    def period(self, periods: int, tick: int) -> None:
        super().period(periods, tick)
        if periods % self.every == 0:
            self._take(wait=False)

    def end(self, result: RunResult | None) -> None:
        """The predicted run is over: its last frames, then the reports until the remote
        run is over, then close."""
        self._drain()
        self._send()
        self._take(wait=True)
        self.close()

    def close(self) -> None:
        if self.closed.is_set():
            return
        if self.reported is not None:
            self.reported.close()
        self.sink.close()
        self.closed.set()

    def _take(self, wait: bool) -> None:
        """Draw what has been reported (``wait``: until the remote run is over)."""
        while not self._over:
            try:
                item = self.inbox.get(block=wait)
            except queue.Empty:
                return
            if item is None:
                self._over = True
            elif self.reported is not None:
                kind, fields = item
                if kind == "sample":
                    self.reported.sample(fields)
                elif kind == "record":
                    self.reported.record(fields)
                else:
                    self.reported.diverged(fields)


def remote_recorder(script: Script, path: Path | None, spawn: bool) -> RemoteRecorder:
    """The recorder of ``--record PATH`` and ``--rerun`` (a spawned viewer)."""
    return RemoteRecorder(RerunSink(path, spawn=spawn), script)
