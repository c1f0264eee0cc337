"""A guarded finger move stops at the physics step where contact is first sensed."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dial.engine as engine
import dial.engine.setup as setup
from dial.backend.driver import MujocoRobot
from dial.parser import load
from dial.scene import load_scene_names

SPEED = 0.02  # m/s
THRESHOLD = 1e-6  # m of taxel depth: "any contact"

# The palm above the block's near edge, facing down, with the pad side of the fingers (the
# thumb's side) toward the block: the index hangs beside the block's near face, and flexing
# it swings its pad into that face. The thumb is curled out of the way above the top.
WORLD = """\
extends = "surface"
[locations]
by_face = { object = "block", pos = [-0.075, 0, 0.12], rpy = [180, 0, -90] }
[programs]
to_side = "MOVE by_face"
[poses.explore]
index = [0, 0, 0, 0]
middle = [0, 0, 0, 0]
ring = [0, 0, 0, 0]
thumb = [0, 80, 90, 60]
"""

SCRIPT = f"""\
@scene world.toml
@tick 0.2
% to    puma_command "ex to_side"
% point hand_pose    "explore"
% down  guarded_move finger=index 1 0 0 frame=world max=40mm speed={SPEED} \
until=tactile:{THRESHOLD * 1000}mm

to    #====
point #----
down       #
"""


class RecordingRobot(MujocoRobot):
    """Records the index fingertip's deepest taxel and height at every guard check."""

    history: list[tuple[int, float, float]]

    def _check_guards(self) -> None:
        if not hasattr(self, "history"):
            self.history = []
        depth = float(self.snapshot().tactile[0].max())
        tip_z = float(self.data.site_xpos[self.index.fingertip_sites[0]][2])
        self.history.append((self.steps, depth, tip_z))
        super()._check_guards()


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[engine.RunResult, RecordingRobot]:
    folder = Path(tmp_path_factory.mktemp("guarded"))
    (folder / "world.toml").write_text(WORLD)
    path = folder / "guarded.dial"
    path.write_text(SCRIPT.replace("\\\n", ""))
    robots: list[RecordingRobot] = []
    original = setup.MujocoRobot

    class Capture(RecordingRobot):
        def __init__(self, *args: object, **kwargs: object) -> None:
            super().__init__(*args, **kwargs)  # type: ignore[arg-type]
            robots.append(self)

    setup.MujocoRobot = Capture  # type: ignore[misc]
    try:
        result = engine.run(load(path, loader=load_scene_names), engine.RunOptions())
    finally:
        setup.MujocoRobot = original  # type: ignore[misc]
    return result, robots[0]


def test_guarded_move_ends_done_on_a_tactile_contact(
    run: tuple[engine.RunResult, RecordingRobot],
) -> None:
    result, _ = run
    assert result.summary.ok, result.summary.error
    (end,) = [r for r in result.log.of("end") if r["event"] == "down"]
    assert end["outcome"] == "done"
    assert end["data"]["kind"] == "tactile" and end["data"]["finger"] == "index"
    assert 0.0 < end["data"]["travel"] < 0.06


def test_stop_is_at_the_first_sensed_step_within_one_step_of_travel(
    run: tuple[engine.RunResult, RecordingRobot],
) -> None:
    result, robot = run
    (contact,) = result.log.of("contact")
    trip_step = contact["step"]
    steps = {step: (depth, z) for step, depth, z in robot.history}
    # The guard fired at the first physics step whose reading passed the threshold...
    first = min(step for step, depth, _ in robot.history if depth >= THRESHOLD)
    assert trip_step == first
    assert steps[trip_step - 1][0] < THRESHOLD
    # ...so contact began at most one physics step before the stop, and the pad had
    # penetrated no further than one physics step of travel at the commanded speed.
    dt = robot.model.opt.timestep
    step_travel = SPEED * dt
    depth_at_trip = steps[trip_step][0]
    assert depth_at_trip <= step_travel + THRESHOLD
    descent = steps[trip_step - 1][1] - steps[trip_step][1]
    assert descent <= 1.5 * step_travel
    # After the stop the fingertip does not keep descending: the set-point froze there.
    later = [z for step, _, z in robot.history if trip_step < step <= trip_step + 50]
    if later:
        assert min(later) >= steps[trip_step][1] - step_travel
    assert np.isfinite(contact["t"])
