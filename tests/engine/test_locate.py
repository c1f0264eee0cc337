"""`locate`: the tool's commanded position corrects an object's believed pose; later moves to
locations relative to it follow the correction, also after a resume from a state file."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import dial

from ..conftest import json_records

WORLD = """\
extends = "surface"
[locations]
above_block = { object = "block", pos = [0, 0, 0.15], rpy = [180, 0, 0] }
"""

# The arm goes over the block, moves 10 mm along world y, says "the block is below me" and
# goes to the location over the block again: it stays where it is. get_wrist records where
# the tool ended.
SCRIPT = """\
@scene world.toml
@tick 0.2
% to     puma_command "moves above_block"
% nudge  arm_move     0 10mm 0 frame=world
% here   locate       "above_block" also=block
% back   puma_command "moves above_block"
% wrist  get_wrist

to     #====

nudge  #=

here   #

back   #==
wrist    #
"""


@pytest.fixture(scope="module")
def script(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = Path(tmp_path_factory.mktemp("locate"))
    (folder / "world.toml").write_text(WORLD)
    path = folder / "locate.dial"
    path.write_text(SCRIPT)
    return path


def _end(result: dial.RunResult, event: str) -> dict[str, object]:
    return next(r for r in result.log.of("end") if r["event"] == event)


def test_locate_shifts_the_belief_and_later_moves_follow(script: Path) -> None:
    result = dial.run(dial.load(script))
    assert result.error is None, result.error
    data = _end(result, "here")["data"]
    assert isinstance(data, dict)
    assert data["objects"] == ["block"]  # also= names the location's own object once
    np.testing.assert_allclose(data["shift"], [0.0, 0.010, 0.0], atol=5e-4)
    wrist = _end(result, "wrist")["data"]
    assert isinstance(wrist, dict) and isinstance(wrist["pos"], list)
    # "back" went to the corrected location, 10 mm along y from the block (which stands on
    # y = 0, docs/scenes.md), not back over the block.
    assert wrist["pos"][1] == pytest.approx(0.010, abs=1e-3)


def test_a_resumed_run_keeps_the_located_belief(script: Path, tmp_path: Path) -> None:
    state = tmp_path / "locate.state"
    full = dial.run(dial.load(script), save_at=(4, state))  # before the block of "back"
    assert full.saved == ((4, state),)
    assert "believed" in json.loads(state.read_text())
    resumed = dial.run(dial.load(script), resume=state)
    tail = [r for r in json_records(resumed) if r["kind"] not in ("scene", "resume")]
    assert tail == json_records(full)[-len(tail) :]
    assert resumed.final_qpos == full.final_qpos
