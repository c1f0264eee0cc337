"""Short scripts on the real engine, for the engine tests."""

from __future__ import annotations

from pathlib import Path

import pytest

# A short run on the surface scene that exercises arm programs, hand poses, a grasp
# that stretches its tick, a guarded move and sensing: enough for the engine tests.
SHORT = """\
@scene surface
@tick 0.1
% to     puma_command "ex to_block"
% open   hand_pose    "open_hand"
% grab   grasp_force  "0x0666_0x0222 2N" timeout=3s
% down   arm_move     0 0 -0.02 frame=world
% joints get_joints
% forces get_forces

to     #====
open   #--
grab        #
down         #=
joints         #
forces         #
"""


@pytest.fixture
def short_script(tmp_path: Path) -> Path:
    path = tmp_path / "short.dial"
    path.write_text(SHORT)
    return path
