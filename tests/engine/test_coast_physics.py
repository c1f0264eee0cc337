"""Coasting on the MuJoCo robot: the same log and the same final state, bit for bit, as
stepping every period one by one (``COAST_FROM`` set out of reach turns coasting off).

reactions.dial coasts with a monitor armed (the driver's per-step loop) and fires it inside a
coast; lightbulb.dial coasts with its thread watched at every physics step; pour's scene
coasts the plain way (one mj_step call per period). A push (``--disturb``) and a perturbed
run cover a disturbance inside a coast and other paths.
"""

from __future__ import annotations

import io
import json
from typing import Any

import pytest

from dial.backend.driver import MujocoRobot
from dial.disturb import parse_disturbance
from dial.engine import RunOptions, run
from dial.parser import load
from dial.resources import resolve_script
from dial.robot.protocol import Report
from dial.scene import load_scene_names
from dial.scheduler import periods


def _run(name: str, **options: object) -> tuple[list[dict[str, object]], list[float]]:
    sink = io.StringIO()
    script = load(resolve_script(name), loader=load_scene_names)
    result = run(script, RunOptions(log=sink, **options))  # type: ignore[arg-type]
    records = [json.loads(line) for line in sink.getvalue().splitlines()]
    records[-1].pop("wall_time")
    return records, result.final_qpos


CASES = {
    "pour": ("pour.dial", {}),
    "reactions": ("reactions.dial", {}),
    "light bulb, perturbed": ("lightbulb.dial", {"perturb_mm": 10.0, "seed": 3}),
    "light bulb, pushed": (
        "lightbulb.dial",
        {"disturb": [parse_disturbance("push body=hand_thumb_distal force=0,5,0 at=1.6 for=0.5")]},
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_coasting_changes_nothing_in_the_log_or_the_state(
    case: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    name, options = CASES[case]
    coasts: list[int] = []
    coast = MujocoRobot.coast

    def counted(robot: MujocoRobot, *args: Any) -> tuple[int, Report | None]:
        done, report = coast(robot, *args)
        coasts.append(done)
        return done, report

    monkeypatch.setattr(MujocoRobot, "coast", counted)
    coasted = _run(name, **options)
    assert sum(coasts) > 100  # periods coasted
    monkeypatch.setattr(periods, "COAST_FROM", 10**9)
    coasts.clear()
    stepped = _run(name, **options)
    assert coasts == []
    assert coasted[0] == stepped[0]
    assert coasted[1] == stepped[1]  # bit for bit
