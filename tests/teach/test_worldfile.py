"""Writing taught names: comments, order and layout kept; atomic with a backup; clashes refused."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from dial.scene import load_world, worlds_dir
from dial.teach.target import NameClash, check_name, open_target
from dial.teach.worldfile import (
    WriteError,
    location_entry,
    pose_entry,
    render,
    write_world,
)

WORLDS = worlds_dir()


def test_rendering_nothing_is_byte_identical() -> None:
    for path in WORLDS.glob("*.toml"):
        text = path.read_text(encoding="utf-8")
        assert render(text, []) == text, path.name


def test_a_change_keeps_every_comment_in_order_and_entries_in_place(
    tmp_path: Path, pour_copy: Path
) -> None:
    path = pour_copy
    before = path.read_text(encoding="utf-8")
    _, moved = location_entry("lid_drop", None, None, (0.4, -0.3, 0.5), (0, 180, 0), False)
    _, added = location_entry("near_cup", "cup", "pour_cup", (0, -0.1, 0.2), (0, 90, 0), False)
    _, pose = pose_entry("pinch", {4 + 1: 20.04, 12 + 1: 10.0})
    after = render(before, [moved, added, pose])
    comments = [line for line in before.splitlines() if line.lstrip().startswith("#")]
    assert [line for line in after.splitlines() if line.lstrip().startswith("#")] == comments
    lines = after.splitlines()
    # lid_drop is replaced where it was; the new location ends [locations]; the new pose
    # follows the file's last pose table.
    old = before.splitlines()
    new_drop = lines.index("lid_drop = { pos = [0.4, -0.3, 0.5], rpy = [0, 180, 0] }")
    old_drop = old.index("lid_drop = { pos = [0.42, -0.3, 0.495], rpy = [0, 180, 0] }")
    assert new_drop - lines.index("[locations]") == old_drop - old.index("[locations]")
    home = lines.index("home = { pos = [0.35, 0, 0.8], rpy = [0, 180, 0] }")
    near = 'near_cup = { object = "cup", pos = [0, -0.1, 0.2], rpy = [0, 90, 0] }'
    assert lines[home + 1] == near
    pinch = lines.index("[poses.pinch]")
    assert lines[pinch + 1 : pinch + 4] == ["middle = { mcp = 20 }", "thumb = { mcp = 10 }", ""]
    assert lines[pinch - 2 : pinch] == ["thumb = [0, -10, 0, 20]", ""]  # knob_open's
    assert lines[pinch + 4] == "[locations]"
    path.write_text(after, encoding="utf-8")
    world = load_world(path)
    assert world.locations["near_cup"].body == "pour_cup"
    assert world.poses["pinch"].angles == {5: pytest.approx(math.radians(20)), 13: math.radians(10)}


def test_replacing_a_pose_keeps_its_table_and_the_comments_above_it(
    tmp_path: Path, pour_copy: Path
) -> None:
    path = pour_copy
    before = path.read_text(encoding="utf-8")
    _, pose = pose_entry("prepit", {k: 5.0 for k in range(4)})  # index only
    after = render(before, [pose])
    start = before.index("[poses.prepit]")
    assert after[:start] == before[:start]
    rest = "[poses.prepit]\nindex = [5, 5, 5, 5]\n\n# Wide open over the lid's knob"  # knob_open's
    assert after[start:].startswith(rest)


def test_entries_round_to_what_is_written() -> None:
    loc, saved = location_entry("x", "lid", "pour_lid", (0.12345, -1e-6, 0.2), (0, -180, 0), True)
    assert saved.items == (
        ("object", '"lid"'),
        ("pos", "[0.1235, 0, 0.2]"),
        ("rpy", "[0, 180, 0]"),
        ("axes", '"world"'),
    )
    assert loc.pos == (0.1235, -0.0, 0.2) and loc.axes == "world"
    assert loc.rpy == (0.0, math.pi, 0.0)
    pose, saved = pose_entry("p", {0: 1.26, 1: 2.0, 2: 3.0, 3: -4.0, 15: 7.77})
    assert saved.items == (("index", "[1.3, 2, 3, -4]"), ("thumb", "{ dip = 7.8 }"))
    assert pose.mask == 0x800F


def test_write_is_atomic_and_keeps_a_backup(tmp_path: Path, pour_copy: Path) -> None:
    path = pour_copy
    old = path.read_bytes()
    _, entry = location_entry("spot", None, None, (0.5, 0, 0.7), (0, 180, 0), False)
    backup = write_world(path, render(old.decode(), [entry]))
    assert backup == tmp_path / "pour_copy.toml.bak" and backup.read_bytes() == old
    assert "spot" in load_world(path).locations
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pour_copy.toml", "pour_copy.toml.bak"]


def test_text_that_would_not_load_is_not_written(tmp_path: Path, pour_copy: Path) -> None:
    path = pour_copy
    old = path.read_bytes()
    bad = old.decode().replace('lid_grasp = { object = "lid"', 'lid_grasp = { object = "hat"')
    with pytest.raises(WriteError, match=r"pour_copy.toml: locations.lid_grasp.object"):
        write_world(path, bad)
    assert path.read_bytes() == old
    assert [p.name for p in tmp_path.iterdir()] == ["pour_copy.toml"]


def test_a_new_into_file_extends_the_scene(tmp_path: Path) -> None:
    world, target = open_target("pour", str(tmp_path / "mine.toml"), tmp_path)
    assert not target.exists and world.path == tmp_path / "mine.toml"
    _, entry = location_entry("spot", "pitcher", "pour_pitcher", (0, 0, 0.3), (0, 180, 0), False)
    assert write_world(target.path, render(target.text, [entry])) is None
    text = target.path.read_text(encoding="utf-8")
    assert 'extends = "pour"\n\n[locations]\nspot = { object = "pitcher"' in text
    mine = load_world(target.path)
    assert "spot" in mine.locations and "lid_grasp" in mine.locations


def test_shared_and_base_names_are_refused_with_the_reason(tmp_path: Path) -> None:
    _, target = open_target("pour", str(tmp_path / "mine.toml"), tmp_path)
    with pytest.raises(NameClash) as e:
        check_name(target, (), "poses", "open_hand", True)
    assert "pose 'open_hand' is defined in the shared hand poses (hand_poses.toml)" in str(e.value)
    assert "choose another name" in str(e.value)
    with pytest.raises(NameClash, match=r"location 'home' is defined in pour\.toml, which mine"):
        check_name(target, (), "locations", "home", True)
    assert check_name(target, (), "locations", "fresh", False) == ""


def test_own_and_session_names_are_replaced_only_when_asked(
    tmp_path: Path, pour_copy: Path
) -> None:
    _, target = open_target(str(pour_copy), None, tmp_path)
    with pytest.raises(NameClash, match=r"already defined in pour_copy\.toml; add 'replace'"):
        check_name(target, (), "locations", "home", False)
    assert "replaces the location" in check_name(target, (), "locations", "home", True)
    # pour.toml's own prepit shadows the shared one: it is the file's to replace.
    assert "replaces the pose" in check_name(target, (), "poses", "prepit", True)
    _, entry = pose_entry("grip", {0: 1.0})
    with pytest.raises(NameClash, match="saved in this session already"):
        check_name(target, (entry,), "poses", "grip", False)
    assert "replaces the pose saved before" in check_name(target, (entry,), "poses", "grip", True)
