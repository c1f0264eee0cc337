"""The bundled scripts on the second robot (allegro_panda), with only the scene changed, one
perturbation each: the surface trace and grasping by containment on each solid, run headless
end to end through the command line (every declared success criterion holds); the light bulb
and the pour with the objects 10 mm off their believed place, where the touch that finds them
works on this hand too (models/allegro_panda/worlds/, docs/robots.md). (The Utah hand's runs
of the same scripts: tests/haptics/, tests/scenarios/test_tasks.py.)"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from numpy.typing import NDArray

import dial
from dial.engine.setup import SETTLE_S

from ..conftest import ROOT
from ..engine.recovery import ended


@pytest.mark.parametrize(
    ("script", "scene", "seed", "criteria"),
    [
        ("explore_surface", "allegro_panda/surface", 1, {"top_plane"}),
        ("containment", "allegro_panda/containment", 1, {"shape_fit"}),
        ("containment", "allegro_panda/containment_cylinder", 2, {"shape_fit"}),
        ("containment", "allegro_panda/containment_rounded", 3, {"shape_fit"}),
    ],
)
def test_a_bundled_script_succeeds_on_the_second_robot(
    script: str, scene: str, seed: int, criteria: set[str]
) -> None:
    command = [sys.executable, "-m", "dial.cli", "run", script, "--scene", scene]
    options = ["--json", "--quiet", "--perturb", "10", "--seed", str(seed)]
    done = subprocess.run(
        [*command, *options], cwd=ROOT, capture_output=True, text=True, timeout=600
    )
    summary = json.loads(done.stdout.splitlines()[-1])
    assert summary["error"] is None, summary["error"]
    success = summary["success"]
    assert isinstance(success, dict) and set(success) == criteria
    assert all(success.values()), summary["criteria"]
    assert summary["ok"] is True and done.returncode == 0


class Offsets:
    """Where an object is from the tool frame (mm, tool axes), sampled every 10 control periods."""

    def __init__(self, body: str) -> None:
        self.body = body
        self.samples: list[tuple[float, NDArray[np.float64]]] = []

    def begin(self, run: dial.Watched) -> None:
        self.robot = run.robot
        self.id = self.robot.model.body(self.body).id

    def period(self, periods: int, tick: int) -> None:
        if periods % 10:
            return
        data, site = self.robot.data, self.robot.index.tool_site
        rot = data.site_xmat[site].reshape(3, 3)
        offset = rot.T @ (data.xpos[self.id] - data.site_xpos[site]) * 1000.0
        self.samples.append((float(data.time), offset))

    def end(self, result: dial.RunResult | None) -> None:
        pass

    def at(self, t: float) -> NDArray[np.float64]:
        """The sample nearest simulated time ``t`` (s from the first tick; the run settles 0.5 s
        before it)."""
        return min(self.samples, key=lambda s: abs(s[0] - 0.5 - t))[1]


def test_lightbulb_on_allegro_panda_when_10mm_off() -> None:
    # Seed 7: the bulb 10 mm off towards the arm's base and its right (225 deg).
    bulb = Offsets("lightbulb_bulb")
    script = dial.load(ROOT / "scripts" / "lightbulb.dial", scene="allegro_panda/lightbulb")
    result = dial.run(script, perturb=10, seed=7, observers=[bulb])
    assert result.ok and result.success == {"bulb_out": True, "bulb_held": True}, result.details
    feels = ended(result, "feel_glass")
    assert [(r["outcome"], r["data"]["finger"]) for r in feels] == [("done", "thumb")] * 2
    # The two feels centre the flange axis (which passes through the pinch) on the glass.
    grasp = next(r for r in result.log.of("start") if r["event"] == "grasp_bulb")
    assert np.hypot(*bulb.at(grasp["t"])[:2]) < 3.0
    # Unscrewed stroke by stroke until a tug came up free: the thread let go before it.
    tugs = ended(result, "tug")
    assert [r["outcome"] for r in tugs] == ["done"] * (len(tugs) - 1) + ["missed"]
    (released,) = result.log.of("thread")
    assert tugs[-2]["t"] < released["t"] < tugs[-1]["t"]
    assert not result.log.of("monitor")


class Touches:
    """The simulated times (s from the first tick) at which two bodies touch, tested every
    control period (:meth:`value`: what is recorded, :meth:`watching`: from when)."""

    def __init__(self, body: str, other: str) -> None:
        self.bodies = (body, other)
        self.values: list[float] = []

    def begin(self, run: dial.Watched) -> None:
        self.robot = run.robot
        self.body, other = (self.robot.model.body(name).id for name in self.bodies)
        self.pair = {self.body, other}

    def watching(self) -> bool:
        return True

    def value(self) -> float:
        return float(self.robot.data.time) - SETTLE_S  # the scene settles before the first tick

    def period(self, periods: int, tick: int) -> None:
        data, model = self.robot.data, self.robot.model
        if not self.watching():
            return
        for c in data.contact[: data.ncon]:
            if {model.geom_bodyid[c.geom1], model.geom_bodyid[c.geom2]} == self.pair:
                self.values.append(self.value())
                return

    def end(self, result: dial.RunResult | None) -> None:
        pass


def test_a_freed_bulb_comes_up_clear_of_the_collar_on_allegro_panda() -> None:
    # Trial 2 of `dial tune ... --perturb 10 --seed 8314` (issue 24). With the pinch 10 mm below
    # the glass centre, the freed bulb's base hung 2.5 mm off the socket's axis, caught the collar
    # as the tug lifted it, the tug read 1.57 N (over its 1.5 N) and the loop went on: the bulb
    # fell back into the socket. At 8 mm (worlds/lightbulb.toml) it comes up clear.
    touches = Touches("lightbulb_bulb", "lightbulb_socket")
    script = dial.load(ROOT / "scripts" / "lightbulb.dial", scene="allegro_panda/lightbulb")
    result = dial.run(script, perturb=10, seed=882851186, observers=[touches])
    assert result.ok and result.success == {"bulb_out": True, "bulb_held": True}, result.details
    tugs = ended(result, "tug")
    assert [r["outcome"] for r in tugs] == ["done"] * 4 + ["missed"]
    # The bulb never touches the socket (at 10 mm it did from 37.71 s, in the first free tug).
    assert not touches.values


def test_pour_on_allegro_panda_when_10mm_off() -> None:
    # Seed 3: the objects 10 mm off, away from the base and towards the cup (31 deg).
    script = dial.load(ROOT / "scripts" / "pour.dial", scene="allegro_panda/pour")
    result = dial.run(script, perturb=10, seed=3)
    poured = {"contents_in_cup": True, "pitcher_upright": True}
    assert result.ok and result.success == poured, result.details
    feels = ended(result, "feel_knob")
    assert [(r["outcome"], r["data"]["kind"]) for r in feels] == [("done", "tactile")] * 2
    (found,) = ended(result, "found")
    (scene,) = result.log.of("scene")
    # The believed lid and pitcher moved to within 3.5 mm of where they truly are (2.7 mm here:
    # the middle's pad, turned 25 deg on the finger's axis, meets the knob 8.6 mm off its centre
    # line at the first feel, and its tilt makes the touch 2.6 mm early; the pitcher's grasp has
    # that much room).
    shift = np.array(found["data"]["shift"][:2]) - np.array(scene["perturb"][:2])
    assert np.linalg.norm(shift) < 0.0035
    grasp = ended(result, "grabpit")[0]["data"]["forces"]
    assert min(grasp.values()) >= 40.0  # middle and thumb both reached the grasp's force


class TableTilts(Touches):
    """The pitcher's tilt (deg) in every control period in which it touches the table, once it
    has been lifted 50 mm (the lift tips it on its edge before it is off)."""

    def __init__(self) -> None:
        super().__init__("pour_pitcher", "pour_table")
        self.lifted = False

    def watching(self) -> bool:
        z = self.robot.data.xpos[self.body][2]
        self.lifted = self.lifted or z > 0.40  # the table top: z 0.35
        return self.lifted

    def value(self) -> float:
        up = min(1.0, float(self.robot.data.xmat[self.body][8]))
        return float(np.degrees(np.arccos(up)))


def test_the_poured_pitcher_meets_the_table_upright_on_allegro_panda() -> None:
    # Trial 17 of `dial tune ... --perturb 10 --seed 8331` (issue 24). The pitcher hangs about
    # 20 mm lower in the pinch after the pour than where it was taken; set 1 mm above the grasp,
    # the straight return put its edge on the table 30 deg from upright, the hand turned it in
    # the pinch about that edge, and a ball that had missed the cup (it landed on the curled
    # ring finger and rode back) lay under it: released, it rested 10.2 deg tipped. With the
    # set-down 20 mm higher and the ring half bent (worlds/pour.toml) the pitcher only ever
    # touches the table upright, and every ball is in the cup.
    tilts = TableTilts()
    script = dial.load(ROOT / "scripts" / "pour.dial", scene="allegro_panda/pour")
    result = dial.run(script, perturb=10, seed=3925225753, observers=[tilts])
    poured = {"contents_in_cup": True, "pitcher_upright": True}
    assert result.ok and result.success == poured, result.details
    assert str(result.details["contents_in_cup"]).startswith("20/20")
    assert tilts.values and max(tilts.values) < 3.0  # 1.9 deg here; 34.9 deg before
