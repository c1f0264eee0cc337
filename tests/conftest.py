"""Shared fixtures: repository paths and golden-file helpers."""

from __future__ import annotations

import atexit
import importlib.util
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

if TYPE_CHECKING:
    from dial import RunResult

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"
UPDATE = os.environ.get("DIAL_UPDATE_GOLDEN") == "1"

# The IK's cache (dial.robot.memo) of this session, and of the processes it starts: a
# folder of its own, empty at the start, never the user's; removed at exit, after the memo
# has written it (atexit runs the later registration first).
if "DIAL_CACHE" not in os.environ:
    os.environ["DIAL_CACHE"] = tempfile.mkdtemp(prefix="dial-test-cache-")
    atexit.register(shutil.rmtree, os.environ["DIAL_CACHE"], True)


def needs(extra: str, *modules: str) -> pytest.MarkDecorator:
    """Skip a test, saying why, when an optional extra it needs is not installed."""
    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    reason = (
        f"the '{extra}' extra is not installed ({', '.join(missing)}): pip install -e '.[{extra}]'"
    )
    return pytest.mark.skipif(bool(missing), reason=reason)


NEEDS_PLOT = needs("plot", "matplotlib")
NEEDS_VIDEO = needs("video", "imageio", "imageio_ffmpeg")
NEEDS_RAY = needs("ray", "ray")


def golden(path: Path, actual: str) -> None:
    """Compare ``actual`` with the golden file; with DIAL_UPDATE_GOLDEN=1, rewrite it."""
    if UPDATE:
        path.write_text(actual, encoding="utf-8")
        return
    assert path.is_file(), f"missing golden file {path}; run with DIAL_UPDATE_GOLDEN=1"
    assert actual == path.read_text(encoding="utf-8")


def json_records(result: RunResult) -> list[dict[str, object]]:
    """A run's log as JSON text would hold it, without the summary's wall time."""
    out = []
    for record in result.log.records:
        record = json.loads(json.dumps(record))
        record.pop("wall_time", None)
        out.append(record)
    return out


@pytest.fixture
def in_root(monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(ROOT)
    return ROOT


# A short run on the surface scene: an arm program, a hand pose, a grasp that stretches its
# tick, a relative arm move and sensing. Enough for the engine and recording tests.
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
