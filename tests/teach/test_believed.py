"""What a run learned, from the shell: `dial run --save-world` writes the believed world into a
world file that keeps the original's comments, and `dial world` reads it; `dial world
--believed LOG` shows it from the run's log. The run is a short one: the arm goes over the
block, moves 10 mm along y and says (`locate`) that the block is below it."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from dial.scene import load_world

DIAL = [sys.executable, "-m", "dial.cli"]

WORLD = """\
# A world for the test: the surface scene, and one location over the block.
extends = "surface"

[objects]
block = "surface_block"   # the block, believed where the model puts it

[locations]
above_block = { object = "block", pos = [0, 0, 0.15], rpy = [180, 0, 0] }
"""

SCRIPT = """\
@scene world.toml
@tick 0.2
% to     puma_command "moves above_block"
% nudge  arm_move     0 10mm 0 frame=world
% here   locate       "above_block" also=block

to     #====

nudge  #=

here   #
"""


def dial(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*DIAL, *args], cwd=cwd, capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def learned(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The folder of a run that saved its world into a sub-folder, with its log."""
    folder = Path(tmp_path_factory.mktemp("believed"))
    (folder / "world.toml").write_text(WORLD)
    (folder / "locate.dial").write_text(SCRIPT)
    (folder / "out").mkdir()
    done = dial("run", "locate.dial", "--quiet", "--json", "--log", "log.jsonl",
                "--save-world", "out/learned.toml", cwd=folder)  # fmt: skip
    summary = json.loads(done.stdout.splitlines()[-1])
    assert summary["error"] is None, done.stderr  # (the surface's plane is never fitted: exit 1)
    return folder


def test_the_saved_world_holds_the_belief_and_keeps_the_file(learned: Path) -> None:
    text = (learned / "out" / "learned.toml").read_text()
    assert text.startswith("# The believed world at the end of `dial run locate.dial`.\n")
    assert "# A world for the test: the surface scene, and one location over the block." in text
    assert "above_block = { object = " in text  # the rest as it was
    assert 'extends = "surface"' in text  # a bundled scene's name stays a name
    entry = next(line for line in text.splitlines() if line.startswith("block = "))
    assert entry.startswith('block = { body = "surface_block", pos = [0.5498, 0.0099, 0.44], ')
    assert entry.endswith("# the block, believed where the model puts it")  # its comment kept
    world = load_world(learned / "out" / "learned.toml")
    prior = world.priors["surface_block"]
    assert prior.pos == pytest.approx((0.55, 0.01, 0.44), abs=5e-4) and prior.size is None


def test_dial_world_reads_the_saved_world(learned: Path) -> None:
    done = dial("world", "out/learned.toml", cwd=learned)
    assert done.returncode == 0, done.stderr
    assert "block  surface_block  pos [549.8, 9.9, 440.0]" in done.stdout


def test_dial_world_believed_shows_belief_beside_truth(learned: Path) -> None:
    done = dial("world", "--believed", "log.jsonl", cwd=learned)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("run log log.jsonl: scene world (")
    block = next(line for line in lines if line.lstrip().startswith("block "))
    assert "believed  pos [549.8, 9.9, 440.0]" in block
    assert "true  pos [550.0, 0.0, 439.8]" in block and block.endswith("off 9.9 mm")
    assert any(" block  locate  pos [550.0, 0.0, 440.0] -> [549.8, 9.9, 440.0]" in line
               for line in lines)  # fmt: skip


@pytest.mark.parametrize(
    ("target", "message"),
    [
        ("missing/learned.toml", "dial: --save-world: cannot write the world file: no such "
         "directory 'missing'"),
        ("learned.txt", "dial: --save-world writes a world file (.toml), not 'learned.txt'"),
    ],
)  # fmt: skip
def test_save_world_to_a_bad_path_is_a_usage_error_before_the_run(
    learned: Path, target: str, message: str
) -> None:
    done = dial("run", "locate.dial", "--log", "never.jsonl", "--save-world", target, cwd=learned)
    assert done.returncode == 2
    assert done.stderr.splitlines()[0] == message
    assert not (learned / "never.jsonl").exists()  # nothing ran


def test_dial_world_needs_a_scene_or_a_log(learned: Path) -> None:
    done = dial("world", cwd=learned)
    assert done.returncode == 2 and "give a SCENE" in done.stderr
    done = dial("world", "surface", "--believed", "log.jsonl", cwd=learned)
    assert done.returncode == 2 and "reads the scene from the log" in done.stderr
