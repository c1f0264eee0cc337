"""World files name their robot (``robot = ...``; the default is the Utah hand on the PUMA),
and every bundled robot's scenes resolve by name."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from dial.scene import WorldFileError, load_world
from dial.scene.resolve import bundled_name, bundled_robot_names, resolve_scene, worlds_dir
from tests.conftest import ROOT

MODELS = ROOT / "models"


def world(tmp_path: Path, robot_line: str) -> Path:
    path = tmp_path / "w.toml"
    model = MODELS / "allegro_panda" / "scene_surface.xml"
    objects = '[objects]\nblock = "surface_block"\n'
    path.write_text(f'{robot_line}\n[scene]\nmodel = "{model}"\n{objects}')
    return path


def test_the_default_robot_is_the_utah_hand_on_the_puma() -> None:
    assert load_world(worlds_dir() / "pour.toml").robot == (MODELS / "utah_hand_puma").resolve()
    assert bundled_robot_names() == ("utah_hand_puma", "allegro_panda")


def test_a_bundled_robot_by_name(tmp_path: Path) -> None:
    assert (
        load_world(world(tmp_path, 'robot = "allegro_panda"')).robot
        == (MODELS / "allegro_panda").resolve()
    )


def test_a_robot_folder_relative_to_the_world_file(tmp_path: Path) -> None:
    shutil.copytree(MODELS / "allegro_panda", tmp_path / "mine" / "hand", dirs_exist_ok=True)
    (tmp_path / "mine" / "worlds").mkdir()
    path = world(tmp_path / "mine" / "worlds", 'robot = "../hand"')
    assert load_world(path).robot == (tmp_path / "mine" / "hand").resolve()
    # ... also through a world file elsewhere that extends it.
    child = tmp_path / "child.toml"
    child.write_text(f'extends = "{path}"\n')
    assert load_world(child).robot == (tmp_path / "mine" / "hand").resolve()


def test_an_unknown_robot(tmp_path: Path) -> None:
    with pytest.raises(WorldFileError) as e:
        load_world(world(tmp_path, 'robot = "allegro"'))
    assert str(e.value) == (
        f"{tmp_path / 'w.toml'}: robot: no robot 'allegro': neither a folder with a robot.toml "
        "nor a bundled robot; bundled robots: utah_hand_puma, allegro_panda"
    )


def test_bundled_names_of_every_robot() -> None:
    pour = resolve_scene("pour", Path.cwd())
    assert pour == worlds_dir() / "pour.toml" and bundled_name(pour) == "pour"
    assert resolve_scene("utah_hand_puma/pour", Path.cwd()) == pour
    for name in ("lib/containment", "hand_poses", "allegro_panda/hand_poses", "x/pour"):
        with pytest.raises(LookupError):
            resolve_scene(name, Path("/"))


def test_a_pose_checked_against_the_worlds_robot_shows_a_small_excess(tmp_path: Path) -> None:
    # The Allegro thumb's opposition joint ends at 1.396 rad (79.98 deg): 80 is just beyond,
    # and the message says by how much rather than "beyond 80 by 0".
    path = world(tmp_path, 'robot = "allegro_panda"')
    path.write_text(path.read_text() + "[poses.p]\nthumb = [80, 0, 0, 0]\n")
    with pytest.raises(WorldFileError) as info:
        load_world(path)
    message = "80 deg is beyond the abd joint's upper limit of 79.98 deg by 0.02 deg"
    assert message in str(info.value)
