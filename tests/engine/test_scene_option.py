"""``dial run --scene``: the chosen scene replaces ``@scene`` for the script and its callees."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from dial.cli import main

from ..conftest import ROOT

WORLDS = ROOT / "models" / "utah_hand_puma" / "worlds"


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def _records(log: Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """The log's scene record and its summary (the run's end, with the chosen scene's criteria)."""
    lines = log.read_text().splitlines()
    scene, summary = json.loads(lines[0]), json.loads(lines[-1])
    assert scene["kind"] == "scene" and summary["kind"] == "summary"
    assert summary["error"] is None  # the run completed; only the criteria (no fits) fail
    return scene, summary


def test_scene_option_replaces_at_scene_in_the_script_and_its_callees(tmp_path: Path) -> None:
    # trace_south exists only in the surface world: with --scene surface the scene-less callee
    # is checked against it and runs in it, although the caller says @scene pour.
    _write(tmp_path / "body.dial", '% go puma_command "moves trace_south"\n\ngo #==\n')
    main_script = _write(
        tmp_path / "main.dial",
        "@scene pour\n@tick 0.05\n% wrist get_wrist\n\nwrist #\n@call body.dial\n",
    )
    log = tmp_path / "log.jsonl"
    assert main(["run", str(main_script), "--scene", "surface", "--quiet", "--log", str(log)]) == 1
    scene, summary = _records(log)
    assert scene["scene"] == "surface" and list(summary["success"]) == ["top_plane"]
    assert summary["outcomes"] == {"done": 2, "runs": 2}  # get_wrist, and the callee's move


def test_scene_option_accepts_a_world_file_path(tmp_path: Path) -> None:
    script = _write(tmp_path / "s.dial", "@tick 0.05\n% wrist get_wrist\n\nwrist #\n")
    log = tmp_path / "log.jsonl"
    world = WORLDS / "containment_cylinder.toml"
    assert main(["run", str(script), "--scene", str(world), "--quiet", "--log", str(log)]) == 1
    scene, summary = _records(log)
    assert scene["world"] == "containment_cylinder.toml"
    assert list(summary["success"]) == ["shape_fit"]


def test_scene_names_are_checked_against_the_chosen_scene(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script = _write(
        tmp_path / "s.dial", '@scene surface\n% go puma_command "moves trace_south"\n\ngo #==\n'
    )
    assert main(["run", str(script), "--scene", "pour"]) == 1
    err = capsys.readouterr().err
    assert "unknown location 'trace_south' in scene 'pour'" in err


def test_unknown_scene_option_is_a_usage_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script = _write(tmp_path / "s.dial", "% wrist get_wrist\n\nwrist #\n")
    assert main(["run", str(script), "--scene", "no_such_scene"]) == 2
    err = capsys.readouterr().err
    assert "'no_such_scene' is neither a file nor a bundled scene" in err and "surface" in err


def test_a_script_without_scene_names_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script = _write(tmp_path / "s.dial", "% wrist get_wrist\n\nwrist #\n")
    assert main(["run", str(script)]) == 1
    assert "add '@scene NAME' or run it with --scene" in capsys.readouterr().err


def test_a_run_in_a_world_file_of_ones_own_replays_from_anywhere(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    mine = tmp_path / "worlds"
    mine.mkdir()
    world = _write(mine / "my_cylinder.toml", 'extends = "containment_cylinder"\n')
    script = _write(tmp_path / "s.dial", "@tick 0.05\n% wrist get_wrist\n\nwrist #\n")
    log, rrd = tmp_path / "logs" / "log.jsonl", tmp_path / "out.rrd"
    log.parent.mkdir()
    args = ["run", str(script), "--scene", str(world), "--quiet", "--log", str(log)]
    assert main([*args, "--log-states"]) == 1
    scene, _ = _records(log)
    assert scene["scene"] == "my_cylinder" and scene["world"] == str(world.resolve())
    monkeypatch.chdir(tmp_path / "logs")  # neither here nor beside the log: found by its path
    assert main(["replay", str(log), "--record", str(rrd)]) == 0
    assert rrd.stat().st_size > 0
