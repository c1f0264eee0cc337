"""The command line: exit statuses, output forms and help."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from dial.cli import main

from .conftest import DATA, ROOT


def test_check_ok_prints_one_line(in_root: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", "scripts/lightbulb.dial", "scripts/pour.dial"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 2
    assert out[0].startswith("scripts/lightbulb.dial: OK")


def test_check_errors_show_source_and_caret(capsys: pytest.CaptureFixture[str]) -> None:
    path = DATA / "invalid" / "unknown_instruction_hint.dial"
    assert main(["check", str(path)]) == 1
    out = capsys.readouterr().out
    assert f"{path}:1:7: unknown instruction 'hand_pos'; did you mean 'hand_pose'?" in out
    assert ' 1 | % pre hand_pos "open_hand"' in out
    assert "   |       ^^^^^^^^" in out


def test_check_reports_every_file(capsys: pytest.CaptureFixture[str]) -> None:
    bad = [str(DATA / "invalid" / n) for n in ("bad_tick.dial", "bad_finger.dial")]
    assert main(["check", *bad]) == 1
    out = capsys.readouterr().out
    assert "bad_tick.dial:1:7:" in out and "bad_finger.dial:1:28:" in out


def test_check_and_show_take_a_scene(in_root: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # explore.dial and the procedures it calls are checked against the chosen scene.
    assert main(["check", "scripts/explore.dial", "--scene", "explore_cylinder"]) == 0
    assert main(["show", "scripts/explore.dial", "--scene", "explore_cylinder"]) == 0
    out = capsys.readouterr().out
    assert "scripts/explore.dial: OK" in out
    assert "scripts/explore.dial: scene explore_cylinder," in out
    assert main(["check", "scripts/explore.dial", "--scene", "pour"]) == 1
    out = capsys.readouterr().out
    assert "unknown program 'to_probe' in scene 'pour'" in out
    assert "unknown program 'to_south' in scene 'pour' (--scene replaces" in out


def test_a_scene_that_does_not_load_is_reported_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text('[scene]\nmodel = "nope.xml"\n[objects]\na = "b"\n')
    # explore.dial calls two scripts: neither repeats the error, nor checks another scene.
    assert main(["check", str(ROOT / "scripts" / "explore.dial"), "--scene", str(bad)]) == 1
    out = capsys.readouterr().out
    assert out.count("has a bad world file") == 1 and out.endswith("explore.dial: 1 error\n")


def test_bundled_script_resolves_by_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["check", "pour.dial"]) == 0
    assert main(["show", "lightbulb"]) == 0
    assert "twist_armCCW" in capsys.readouterr().out


def test_missing_script_is_a_clear_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["show", "no_such_script.dial"]) == 1
    err = capsys.readouterr().err
    assert "no such script 'no_such_script.dial'" in err and "pour.dial" in err


def test_fmt_rewrites_in_place_and_check_mode(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "x.dial"
    path.write_text('%  go   puma_command   "moves  above"\n\ngo     #==\n')
    assert main(["fmt", "--check", str(path)]) == 1
    assert main(["fmt", str(path)]) == 0
    assert path.read_text() == '% go puma_command "moves above"\n\ngo #==\n'
    assert main(["fmt", "--check", str(path)]) == 0


def test_fmt_refuses_a_script_that_does_not_parse(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "x.dial"
    path.write_text("go #=x\n")
    assert main(["fmt", str(path)]) == 1
    assert "x.dial:1:6: unexpected 'x'" in capsys.readouterr().err
    assert path.read_text() == "go #=x\n"


def test_usage_error_exits_2() -> None:
    with pytest.raises(SystemExit) as info:
        main(["show"])
    assert info.value.code == 2


@pytest.mark.parametrize("sub", [[], ["check"], ["show"], ["fmt"]])
def test_help_describes_options(sub: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main([*sub, "--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    assert "usage: dial" in out
    if sub == ["fmt"]:
        assert "--check" in out


def test_console_script_is_installed() -> None:
    exe = shutil.which("dial")
    assert exe is not None, "the 'dial' console script is not on PATH; pip install -e ."
    done = subprocess.run(
        [exe, "check", "scripts/pour.dial"], cwd=ROOT, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stdout + done.stderr


def test_parser_imports_neither_mujoco_nor_trio() -> None:
    code = (
        "import sys, dial.parser, dial.parser.fmt, dial.parser.show, dial.instructions\n"
        "bad = [m for m in ('mujoco', 'trio', 'mink') if m in sys.modules]\n"
        "assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
