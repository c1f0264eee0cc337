"""``dial run --remote --record/--rerun``: the predicted robot and the reported one together.

The prediction's run is recorded as a local run is (its robot, its lanes, its log). The
reported robot is drawn beside it from the telemetry, in the same recording: its arm and
hand under ``world/reported`` (a replica of the scene's model posed with the reported joint
angles), and its event lanes, from the reported records, under ``reported``. Both are on
the same simulated-time and tick timelines.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from dial.backend.model import RobotIndex, load_model
from dial.parser.lanes import LanePlan
from dial.parser.script import Script
from dial.recording.geometry import body_paths, moving_bodies
from dial.recording.lanes import Lanes
from dial.recording.observers import Recorder
from dial.recording.rerun_sink import RerunSink
from dial.remote.protocol import Message
from dial.scene.of_script import script_world
from dial.scheduler.log import Record

REPORTED = "reported"


class SharedSink(RerunSink):
    """A sink the prediction's recorder does not close: the reported robot goes on."""

    def close(self) -> None:
        pass

    def finish(self) -> None:
        super().close()


class ReportedRobot:
    """The reported robot and its lanes, drawn into the prediction's recording."""

    def __init__(self, sink: SharedSink, script: Script) -> None:
        world = script_world(script)
        self.sink = sink
        self.model = load_model(world.model_path)
        self.data = mujoco.MjData(self.model)
        mujoco.mj_forward(self.model, self.data)
        self.index = RobotIndex.from_model(self.model)
        paths = body_paths(self.model, world.objects)
        robot = [int(b) for b in moving_bodies(self.model) if paths[b].startswith(("arm", "hand"))]
        self.paths = {b: f"world/{REPORTED}/{paths[b]}" for b in robot}
        sink.ghost(self.model, self.paths)
        self.lanes = Lanes(LanePlan.from_script(script))

    def sample(self, msg: Message) -> None:
        arm = [float(x) for x in msg.items("arm") if isinstance(x, int | float)]
        hand = [float(x) for x in msg.items("hand") if isinstance(x, int | float)]
        if len(arm) != len(self.index.arm_qpos) or len(hand) != len(self.index.hand_qpos):
            return
        self.data.qpos[self.index.arm_qpos] = np.array(arm)
        self.data.qpos[self.index.hand_qpos] = np.array(hand)
        mujoco.mj_kinematics(self.model, self.data)
        self.sink.poses(msg.number("t"), msg.integer("tick"), self.paths, self.data)

    def record(self, record: Record) -> None:
        self.sink.phases(self.lanes.feed(record), (REPORTED,))

    def finish(self) -> None:
        self.sink.phases(self.lanes.flush(), (REPORTED,))
        self.sink.finish()


def recording(script: Script, path: Path | None, spawn: bool) -> tuple[Recorder, ReportedRobot]:
    """The prediction's recorder and the reported robot, sharing one sink."""
    sink = SharedSink(path, spawn=spawn)
    plan = LanePlan.from_script(script)
    return Recorder(sink, Path(script.path).name, plan=plan), ReportedRobot(sink, script)
