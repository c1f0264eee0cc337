"""A remote session on the second robot (allegro_panda): the world's robot is the robot's at
both ends, and with no intervention the robot's log is a local run's."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

from tests.remote.helpers import ROOT, dial, env, robot_log, run_operator, server

SCRIPT = ROOT / "tests" / "robots" / "allegro_touch.dial"


def test_a_world_on_the_second_robot_runs_remotely_as_locally(tmp_path: Path) -> None:
    script = SCRIPT
    args = ("--perturb", "5", "--seed", "4")
    with server(tmp_path / "a", *args, pace=0.2) as srv:
        code, summary, err = run_operator(srv, str(script), log=tmp_path / "op.jsonl")
        robot = robot_log(srv.records())
    local = tmp_path / "local.jsonl"
    subprocess.run(dial("run", str(script), "--quiet", "--log", str(local), *args), env=env())
    expected = [json.loads(line) for line in local.read_text().splitlines()]
    assert robot == [{k: v for k, v in r.items() if k != "wall_time"} for r in expected]
    assert code == 1, err  # the script feels the block and fits no plane: a criterion fails
    assert robot[0]["kind"] == "scene" and robot[0]["world"] == "allegro_panda/surface.toml"
    assert summary is not None and summary["outcomes"] == {"done": 3, "runs": 3}, summary
