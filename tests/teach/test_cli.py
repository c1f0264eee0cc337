"""`dial teach` and `dial world` from the shell: scripted sessions, files, pictures, errors."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from dial.cli import main
from dial.scene import load_world
from dial.teach.commands import SPECS

DIAL = [sys.executable, "-m", "dial.cli"]

# Jog from the start pose (home) over the pitcher and down beside the lid's knob; close middle
# finger and thumb on the knob and let them settle there; save both, and write.
SESSION = """\
# Teach a pinch on the lid's knob, from the start pose (home).
pose open_hand
jog 240 -120 -100      # over the pitcher, 80 mm above the knob
jog z -79              # down beside the knob
save location knob_grip relative-to pitcher
finger middle mcp 15   # close middle and thumb onto the knob
finger thumb mcp 15
limp middle thumb      # let them come to rest on it
save pose knob_pinch fingers=0xF0F0
write
"""

# The paper's pour (scripts/pour.dial without its feeling and its watch) with the lid taken at
# the taught location, closing to the taught pose before the grasp with force.
SCRIPT = """\
@scene taught.toml
@tick 0.25

% approach    puma_command "appro knob_grip 0.10"
% descend     puma_command "moves knob_grip"
% open        hand_pose    "open_hand"
% pinch       hand_pose    "knob_pinch"
% grab_top    grasp_force  "0x6060_0x2020 8N"
% lift_top    puma_command "ex lift_top"
% to_grasp    puma_command "ex to_grasp"
% prepit      hand_pose    "prepit"
% grabpit     grasp_force  "0x6060_0x2020 40N"
% pourpit     puma_command "ex pour"
% retract_arm puma_command "ex retract_arm"
% lower_pit   puma_command "moves pitcher_grasp"

approach    #========
descend              #===
open        #------------            #---
pinch                    #
grab_top                  #
lift_top                   #=========
to_grasp                                 #======
lower_pit                                       #==
prepit                                   #------            #---
grabpit                                            #
pourpit                                             #=======
retract_arm                                                     #=====
"""


def dial(*args: str, stdin: str = "", cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["MUJOCO_GL"] = "egl"
    return subprocess.run(
        [*DIAL, *args], input=stdin, capture_output=True, text=True, env=env, cwd=cwd, timeout=300
    )


def test_a_scripted_session_teaches_names_that_a_new_script_runs_with(tmp_path: Path) -> None:
    taught = tmp_path / "taught.toml"
    done = dial("teach", "--scene", "pour", "--into", str(taught), stdin=SESSION)
    assert done.returncode == 0, done.stdout + done.stderr
    echo = "teach> jog z -79              # down beside the knob\n"
    assert echo + "tool  pos [590.0, -120.0, 621.0]" in done.stdout
    assert f"wrote knob_grip, knob_pinch to {taught}" in done.stdout
    world = load_world(taught)
    grip = world.locations["knob_grip"]
    assert grip.body == "pour_pitcher"  # relative to the pitcher, 271 mm above its base
    assert grip.pos == pytest.approx((0.0, 0.0, 0.2712), abs=3e-4)
    assert world.poses["knob_pinch"].mask == 0xF0F0
    assert "lid_grasp" in world.locations  # the rest comes from the scene it extends
    assert taught.read_text().startswith("# Poses and locations taught with `dial teach")

    script = tmp_path / "lid_taught.dial"
    script.write_text(SCRIPT)
    checked = dial("check", str(script))
    assert checked.returncode == 0, checked.stdout
    log = tmp_path / "run.jsonl"
    ran = dial("run", str(script), "--json", "--quiet", "--log", str(log))
    assert ran.returncode == 0, ran.stdout + ran.stderr
    summary = json.loads(ran.stdout.splitlines()[-1])
    assert summary["success"] == {"contents_in_cup": True, "pitcher_upright": True}
    records = [json.loads(line) for line in log.read_text().splitlines()]
    grab = next(r for r in records if r["kind"] == "end" and r["event"] == "grab_top")
    # From the taught pinch, the grasp felt the knob: both tendons reached 8 N.
    assert grab["outcome"] == "done" and min(grab["data"]["forces"].values()) >= 8.0


def test_write_without_changes_leaves_the_file_byte_identical(
    tmp_path: Path, pour_copy: Path
) -> None:
    path = pour_copy
    before = path.read_bytes()
    done = dial("teach", "--scene", str(path), stdin="jog z -10\nwrite\nquit\n")
    assert done.returncode == 0, done.stderr
    assert f"nothing to write: {path} is unchanged" in done.stdout
    assert path.read_bytes() == before
    assert not (tmp_path / "pour_copy.toml.bak").exists()


def test_a_change_keeps_the_comments_and_a_backup(tmp_path: Path, pour_copy: Path) -> None:
    path = pour_copy
    before = path.read_text()
    session = "jog z -20\nsave location low\nsave location home replace\nwrite\n"
    done = dial("teach", "--scene", str(path), stdin=session)
    assert done.returncode == 0, done.stderr
    after = path.read_text()
    comments = [line for line in before.splitlines() if line.startswith("#")]
    assert [line for line in after.splitlines() if line.startswith("#")] == comments
    assert "low = { pos = [0.35, 0, 0.78], rpy = [0, 180, 0] }" in after
    assert "\nhome = { pos = [0.35, 0, 0.78], rpy = [0, 180, 0] }\nlow = " in after
    assert (tmp_path / "pour_copy.toml.bak").read_text() == before


def test_end_of_input_with_names_not_written_exits_1_and_prints_them(
    tmp_path: Path, pour_copy: Path
) -> None:
    path = pour_copy
    before = path.read_bytes()
    done = dial("teach", "--scene", str(path), stdin="jog z -20\nsave location low\nquit\n")
    assert done.returncode == 1
    assert "error: 1 saved name (low) not written to pour_copy.toml" in done.stdout
    assert "not written to" in done.stderr
    assert "[locations]\nlow = { pos = [0.35, 0, 0.78], rpy = [0, 180, 0] }" in done.stderr
    assert path.read_bytes() == before
    done = dial("teach", "--scene", str(path), stdin="save location low\n")
    assert done.returncode == 1 and "end of input" in done.stderr


def test_a_refused_command_stops_a_script_and_says_why(tmp_path: Path) -> None:
    done = dial("teach", "--scene", "surface", stdin="goto above_block\njog z -200\nwrite\n")
    assert done.returncode == 1
    assert "error: refused: " in done.stdout and "into surface_block" in done.stdout
    assert "teach> write" not in done.stdout
    assert "stopped at 'jog z -200'" in done.stderr


def test_a_shared_name_is_refused(tmp_path: Path) -> None:
    into = str(tmp_path / "x.toml")
    done = dial("teach", "--scene", "pour", "--into", into, stdin="save pose fist\n")
    assert done.returncode == 1
    assert "error: pose 'fist' is defined in the shared hand poses (hand_poses.toml)" in done.stdout
    assert not (tmp_path / "x.toml").exists()


def test_snapshots_after_each_command(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib", reason="the 'plot' extra is not installed")
    shots = tmp_path / "shots"
    done = dial("teach", "--scene", "surface", "--snapshot", str(shots), stdin="jog z -20\nwhere\n")
    assert done.returncode == 0, done.stderr
    names = sorted(p.name for p in shots.iterdir())
    assert names == ["001-start.png", "002-jog_z_-20.png", "003-where.png"]
    assert all((shots / n).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for n in names)


def test_viewer_without_a_display_is_one_line(tmp_path: Path) -> None:
    done = dial("teach", "--scene", "pour", "--viewer")
    assert done.returncode == 1
    assert done.stderr.startswith("dial: --viewer needs a display")
    assert done.stderr.endswith("; use --snapshot DIR instead\n")  # not dial run's --record
    assert "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_usage_errors_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["teach", "--scene", "nowhere"]) == 2
    assert "--scene: 'nowhere' is neither a file nor a bundled scene" in capsys.readouterr().err
    assert main(["world", "nowhere"]) == 2
    assert capsys.readouterr().err.startswith("dial: SCENE: 'nowhere' is neither a file")
    assert main(["world", "pour", "--picture", "x.jpg"]) == 2
    assert "--picture writes a .png file" in capsys.readouterr().err
    assert main(["teach", "--scene", "pour", "--viewer", "--snapshot", "d"]) == 2


def test_teach_help_lists_every_command(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["teach", "--help"])
    out = capsys.readouterr().out
    for spec in SPECS.values():
        assert spec.usage in out


def test_world_lists_the_scene(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["world", "pour"]) == 0
    out = capsys.readouterr().out
    assert "  pitcher  pour_pitcher  pos [590.0, -120.0, 350.0]  rpy [0.0, 0.0, 0.0]" in out
    assert "  open_hand   0xFFFF  index [0, 5, 5, 5]  middle [0, 5, 5, 5]" in out
    assert "  unscrew     0x1111  index {abd -15}" in out
    line = next(x for x in out.splitlines() if x.startswith("  pitcher_grasp "))
    assert "pos [480.0, -120.0, 440.0]  rpy [0.0, 90.0, 0.0]" in line
    assert line.endswith("relative to pitcher: pos [-110.0, 0.0, 90.0] rpy [0.0, 90.0, 0.0]")
    home = "  home            pos [350.0, 0.0, 800.0]     rpy [0.0, 180.0, 0.0]      absolute"
    assert home in out
    assert "  to_grasp     DEPART 80mm; MOVE beside_pitcher; MOVES pitcher_above\n" in out
    assert "  pitcher_upright  upright             object=pour_pitcher max_tilt_deg=10" in out
    assert "thread" not in out
    assert main(["world", "lightbulb_long"]) == 0
    assert "\nthread 3.5 turns until it lets go\n" in capsys.readouterr().out


def test_world_picture(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib", reason="the 'plot' extra is not installed")
    picture = tmp_path / "pour_world.png"
    done = dial("world", "pour", "--picture", str(picture))
    assert done.returncode == 0, done.stderr
    assert f"{picture}: 10 location frames drawn" in done.stderr
    from matplotlib.image import imread

    image = imread(picture)
    assert image.shape[:2] == (960, 1280)


def test_world_of_a_taught_file(tmp_path: Path, pour_copy: Path) -> None:
    shutil.copy(pour_copy, tmp_path / "base.toml")
    (tmp_path / "mine.toml").write_text(
        'extends = "base.toml"\n[locations]\nhere = { object = "lid", pos = [0, 0, 0.1], '
        'rpy = [0, 180, 0], axes = "world" }\n'
    )
    done = dial("world", "mine.toml", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "relative to lid, world axes: pos [0.0, 0.0, 100.0] rpy [0.0, 180.0, 0.0]" in done.stdout
