"""dial's errors cross process boundaries whole (a worker's error reaches its parent through
pickle): each made from parts, not from its message, pickles as those parts."""

from __future__ import annotations

import pickle
import shutil
from pathlib import Path

import pytest

from dial.errors import DialError, ScriptError
from dial.parser import check_text
from dial.robots.profile import RobotFileError, load_profile
from dial.scene.reader import WorldFileError
from dial.scene.resolve import models_dir
from dial.scene.world import load_world


def _raised(make: object) -> DialError:
    with pytest.raises(DialError) as caught:
        make()  # type: ignore[operator]
    return caught.value


def _round_trip(error: DialError) -> DialError:
    copy = pickle.loads(pickle.dumps(error))
    assert type(copy) is type(error)
    assert str(copy) == str(error)
    return copy  # type: ignore[no-any-return]


def test_a_script_error_keeps_its_diagnostics() -> None:
    error = _raised(lambda: check_text("% a hand_pose\n% a hand_pose\nb #\n", "bad.dial"))
    assert isinstance(error, ScriptError) and len(error.diagnostics) >= 2
    copy = _round_trip(error)
    assert isinstance(copy, ScriptError) and copy.diagnostics == error.diagnostics


def test_a_world_file_error_keeps_its_path_and_key(tmp_path: Path) -> None:
    world = tmp_path / "w.toml"
    world.write_text('extends = "pour"\n[criteria]\ncontents_in_cup = 3\n')
    error = _raised(lambda: load_world(world))
    copy = _round_trip(error)
    assert isinstance(copy, WorldFileError)
    assert (copy.path, copy.key) == (str(world), "criteria.contents_in_cup")


def test_a_robot_file_error_keeps_its_diagnostics(tmp_path: Path) -> None:
    folder = tmp_path / "robot"
    shutil.copytree(models_dir() / "allegro_panda", folder, ignore=shutil.ignore_patterns("worlds"))
    toml = folder / "robot.toml"
    toml.write_text(toml.read_text().replace('tip_site = "allegro_index_tip"', "tip_site = 3"))
    error = _raised(lambda: load_profile(folder))
    copy = _round_trip(error)
    assert isinstance(copy, RobotFileError) and isinstance(error, RobotFileError)
    assert copy.render() == error.render()
