"""``dial check`` reads a scene's model without MuJoCo: a malformed model, or a world object
that names no body, is a caret error at ``@scene`` (issue 15), not a traceback at run time."""

from __future__ import annotations

from pathlib import Path

import pytest

from dial.backend.model import load_model, profile_at
from dial.errors import ScriptError
from dial.parser import check_text
from dial.scene import bundled_scene_names, load_scene_names, load_world, models_dir
from dial.scene.mjcf import body_names
from dial.scene.resolve import bundled_world

from .conftest import write

SCENE_XML = (models_dir() / "utah_hand_puma" / "scene_surface.xml").as_posix()
SCRIPT = '@scene w.toml\n% go puma_command "moves above_block"\n\ngo #\n'


@pytest.mark.parametrize("name", bundled_scene_names())
def test_body_names_are_those_mujoco_compiles(name: str) -> None:
    world = load_world(bundled_world(name))
    model = load_model(world.model_path, profile_at(world.robot))
    compiled = {model.body(i).name for i in range(model.nbody)} - {"world"}
    assert body_names(world.model_path) == compiled


def _check(tmp_path: Path, model: str, block: str = "surface_block") -> list[str]:
    write(
        tmp_path / "w.toml",
        f'extends = "surface"\n[scene]\nmodel = "{model}"\n[objects]\nblock = "{block}"\n',
    )
    with pytest.raises(ScriptError) as info:
        check_text(SCRIPT, str(tmp_path / "s.dial"), loader=load_scene_names)
    return [d.header for d in info.value.diagnostics]


def test_a_malformed_model_is_an_error_at_scene(tmp_path: Path) -> None:
    write(tmp_path / "scene.xml", f'<mujoco>\n  <include file="{SCENE_XML}"/>\n  <worldbody>\n')
    (header,) = _check(tmp_path, "scene.xml")
    assert header.startswith(f"{tmp_path / 's.dial'}:1:8: scene 'w.toml' has a bad world file: ")
    assert header.endswith(f"{tmp_path / 'scene.xml'}: malformed XML at line 4, column 1")


def test_a_missing_include_is_an_error_at_scene(tmp_path: Path) -> None:
    write(tmp_path / "scene.xml", '<mujoco><include file="gone.xml"/></mujoco>')
    (header,) = _check(tmp_path, "scene.xml")
    assert header.endswith(f"{tmp_path / 'scene.xml'}: model file 'gone.xml' not found")


def test_an_object_naming_no_body_is_an_error_at_scene(tmp_path: Path) -> None:
    (header,) = _check(tmp_path, SCENE_XML, block="surface_blok")
    assert header.endswith(
        f"{tmp_path / 'w.toml'}: objects.block: no body 'surface_blok' in scene_surface.xml; "
        "did you mean 'surface_block' or 'surface_table'?"
    )


def test_a_model_only_mujoco_refuses_is_one_line_at_run_time(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from dial.cli import main

    geom = '<worldbody><geom type="sphere" size="abc" pos="3 3 3"/></worldbody>'
    write(tmp_path / "scene.xml", f'<mujoco>\n  <include file="{SCENE_XML}"/>\n  {geom}\n</mujoco>')
    write(tmp_path / "w.toml", 'extends = "surface"\n[scene]\nmodel = "scene.xml"\n')
    write(tmp_path / "s.dial", "@scene w.toml\n% t get_joints\nt #\n")
    assert main(["check", str(tmp_path / "s.dial")]) == 0  # well-formed, its bodies are there
    capsys.readouterr()
    assert main(["run", str(tmp_path / "s.dial"), "--quiet"]) == 1
    assert capsys.readouterr().err == (
        f"dial: {tmp_path / 'scene.xml'}: MuJoCo cannot compile the model: XML Error: bad "
        "format in attribute 'size'; Element 'geom', line 3\n"
    )
