"""``dial preview`` from the shell: exit statuses, the problem lines, the storyboard."""

from __future__ import annotations

import os
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from dial.cli import main

from ..conftest import NEEDS_PLOT

DIAL = [sys.executable, "-m", "dial.cli"]


def dial(*args: str) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["MUJOCO_GL"] = "egl"
    return subprocess.run([*DIAL, *args], capture_output=True, text=True, env=env, timeout=300)


def test_pour_passes(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["preview", "pour.dial"]) == 0
    out = capsys.readouterr().out
    assert out == (
        "pour.dial: preview OK: 15 blocks, 21 arm targets, 6 hand targets"
        " (2 @on reactions, 7 loops once each)\n"
    )


def test_a_location_moved_out_of_reach_fails_naming_it_and_its_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    far = tmp_path / "far.toml"
    far.write_text(
        'extends = "pour"\n\n[locations]\n'
        'lid_grasp = { object = "lid", pos = [1.9, 0, 0.121], rpy = [0, 180, 0] }  # far away\n'
    )
    assert main(["preview", "pour.dial", "--scene", str(far)]) == 1
    lines = capsys.readouterr().out.splitlines()
    reach = [line for line in lines if "'lid_grasp'" in line and "out of the arm's reach" in line]
    assert len(reach) == 1
    place, event = reach[0].split(": ")[:2]
    path, line, col = place.rsplit(":", 2)
    assert event == "get_top"
    assert Path(path).read_text().splitlines()[int(line) - 1][int(col) - 1 :].startswith("#====")
    assert lines[-1].startswith("pour.dial: 6 problems: ")


def test_notes_are_printed_on_request(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["preview", "explore.dial"]) == 0
    out = capsys.readouterr().out
    assert "note:" not in out and out.rstrip().endswith("notes on paths not taken")
    assert main(["preview", "explore.dial", "--notes"]) == 0
    notes = [line for line in capsys.readouterr().out.splitlines() if ": note: " in line]
    assert notes and all("of explore.dial:" in note for note in notes)


def test_the_storyboard_is_a_png_of_one_panel_per_block(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib", reason="the 'plot' extra is not installed")
    png = tmp_path / "reactions.png"
    done = dial("preview", "reactions.dial", "--storyboard", str(png))
    assert done.returncode == 0, done.stderr
    assert done.stderr == f"{png}: 3 panels\n"
    head = png.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR"
    width, height = struct.unpack(">II", head[16:24])
    assert (width, height) == (3 * 488 + 8, 44 + 360 + 46 + 8)


@NEEDS_PLOT  # without the extra, that is said first
def test_storyboard_usage_errors(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("MUJOCO_GL", "egl")  # what the command sets before MuJoCo loads
    assert main(["preview", "pour.dial", "--storyboard", str(tmp_path / "x.jpg")]) == 2
    assert "--storyboard writes a .png file" in capsys.readouterr().err
    missing = tmp_path / "no" / "x.png"
    assert main(["preview", "pour.dial", "--storyboard", str(missing)]) == 1
    assert capsys.readouterr().err == (
        f"dial: cannot write the storyboard: no such directory '{missing.parent}'\n"
    )


def test_help_lists_the_options(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["preview", "--help"])
    out = capsys.readouterr().out
    for option in ("--scene", "--storyboard", "--notes"):
        assert option in out
