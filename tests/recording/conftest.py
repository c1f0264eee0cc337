"""A short run on the surface scene, for the recording tests."""

from __future__ import annotations

from pathlib import Path

import pytest

# Arm program, hand pose, a grasp that stretches its tick, a move and sensing: about 1 s of
# simulated time, with starts, ends and a stretched tick in the log.
SHORT = """\
@scene surface
@tick 0.1
% to     puma_command "ex to_block"
% open   hand_pose    "open_hand"
% grab   grasp_force  "0x0666_0x0222 2N" timeout=3s
% down   arm_move     0 0 -0.02 frame=world
% forces get_forces

to     #====
open   #--
grab        #
down         #=
forces         #
"""


@pytest.fixture
def short_script(tmp_path: Path) -> Path:
    path = tmp_path / "short.dial"
    path.write_text(SHORT)
    return path


def without_wall_time(log: Path) -> list[str]:
    """The log's lines, with the summary's wall time (its one wall-clock field) blanked."""
    lines = log.read_text().splitlines()
    assert lines[-1].startswith('{"kind":"summary"')
    head, _, tail = lines[-1].partition('"wall_time":')
    return [*lines[:-1], head + tail.partition(",")[2]]
