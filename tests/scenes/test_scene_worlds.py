"""World files: bundled scenes, the format, and error messages that name file and key."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest

from dial.instructions.scene_names import SceneNotFoundError
from dial.scene import (
    Appro,
    Depart,
    Move,
    PlaneFit,
    WorldFileError,
    bundled_scene_names,
    load_scene_names,
    load_world,
    models_dir,
    resolve_scene,
    worlds_dir,
)

from .conftest import write

SCENES = (
    "containment",
    "containment_cylinder",
    "containment_rounded",
    "explore_block",
    "explore_cylinder",
    "explore_rounded",
    "lightbulb",
    "lightbulb_long",
    "pour",
    "reactions",
    "surface",
)
PAPER_PROGRAMS = {
    "lightbulb": {"to_bulb", "lower_to_bulb", "twist_wrist", "twist_CW", "retract_arm"},
    "pour": {"get_top", "lift_top", "to_grasp", "pour", "retract_arm"},
}
# The quarter turns lightbulb.dial and pour.dial ask of the arm's last joint (the PUMA's joint
# 6), as world programs so that the scripts run on another arm.
TURNS = {"lightbulb": {"turn_probe", "turn_back"}, "pour": {"turn_wrist", "turn_back"}}
PAPER_POSES = {"open_hand", "prelight", "unscrew", "ungrasp", "point", "prepit"}


def test_models_dir_is_the_checkout_models_folder() -> None:
    assert (models_dir() / "utah_hand_puma" / "objects_pour.xml").is_file()
    names = bundled_scene_names()
    assert names[: len(SCENES)] == SCENES  # the first robot's, by name; then the others'
    assert all(n.startswith("allegro_panda/") for n in names[len(SCENES) :])


@pytest.mark.parametrize("name", SCENES)
def test_bundled_worlds_load(name: str) -> None:
    world = load_world(resolve_scene(name, Path("/nonexistent")))
    assert world.name == name and world.model_path.is_file()
    assert set(world.poses) >= PAPER_POSES
    assert set(world.programs) >= PAPER_PROGRAMS.get(name, set())
    assert world.criteria


def test_load_scene_names_reports_masks_locations_programs() -> None:
    names = load_scene_names("lightbulb", Path.cwd())
    assert names.name == "lightbulb"
    assert names.poses["prelight"] == 0xFFFF
    assert names.poses["unscrew"] == 0x1010  # middle and thumb abduction: the grip is kept
    assert names.poses["ungrasp"] == 0xEEEF  # flexion, and the index abducts with the middle
    assert names.poses["point_down"] == 0x000F
    assert "above_bulb" in names.locations
    assert names.programs == PAPER_PROGRAMS["lightbulb"] | TURNS["lightbulb"]


def test_scene_path_wins_over_bundled_name(tmp_path: Path) -> None:
    (tmp_path / "pour").write_text("")  # a file named like a bundled scene
    assert resolve_scene("pour", tmp_path) == tmp_path / "pour"
    assert resolve_scene("pour", tmp_path / "elsewhere") == worlds_dir() / "pour.toml"


def test_unknown_scene_lists_the_bundled_names(tmp_path: Path) -> None:
    with pytest.raises(SceneNotFoundError, match="unknown scene 'kitchen'") as e:
        load_scene_names("kitchen", tmp_path)
    assert "containment, containment_cylinder, containment_rounded, explore_block" in str(e.value)


def test_containment_variants_change_only_the_target() -> None:
    box = load_world(worlds_dir() / "containment.toml")
    cyl = load_world(worlds_dir() / "containment_cylinder.toml")
    assert box.locations["over_top"].body == "containment_box"
    assert cyl.locations["over_top"].body == "containment_cylinder"
    assert cyl.criteria[0].body == "containment_cylinder"  # type: ignore[attr-defined]
    assert cyl.model_path == box.model_path and cyl.poses == box.poses


def test_values_are_converted_to_si() -> None:
    pour = load_world(worlds_dir() / "pour.toml")
    assert pour.poses["prelight"].angles[1] == pytest.approx(math.radians(20))
    grasp = pour.locations["pitcher_grasp"]
    assert grasp.body == "pour_pitcher" and grasp.axes == "object"
    assert grasp.rpy == pytest.approx((0, math.pi / 2, 0))
    # Pitch 90 deg about y: w = x = cos 45 deg... as a quaternion (w, x, y, z).
    assert grasp.quat == pytest.approx((math.sqrt(0.5), 0, math.sqrt(0.5), 0))
    down = pour.locations["home"]
    assert down.body is None and down.quat == pytest.approx((0, 0, 1, 0), abs=1e-12)
    program = pour.programs["pour"].statements
    assert program == (Move(1, "pour_over_cup", True), Move(2, "pitcher_set", True))
    tipped = pour.locations["pour_over_cup"].rpy
    assert tipped == pytest.approx(tuple(math.radians(a) for a in (-90, -30, -90)))
    assert load_world(worlds_dir() / "pour.toml").programs["get_top"].statements == (
        Appro(1, "lid_grasp", 0.10),
        Move(2, "lid_grasp", straight=True),
    )
    surface = load_world(worlds_dir() / "surface.toml")
    (plane,) = surface.criteria
    assert isinstance(plane, PlaneFit)
    assert plane.normal_tol == pytest.approx(math.radians(2)) and plane.extent_tol == 0.005
    assert surface.programs["retract_arm"].statements == (Depart(1, 0.15),)


# Errors ------------------------------------------------------------------------------------

HEAD = """
[scene]
model = "{model}"
poses = "{poses}"

[objects]
block = "surface_block"
"""


def _world(tmp_path: Path, body: str) -> Path:
    head = HEAD.format(
        model=(models_dir() / "utah_hand_puma" / "scene_surface.xml").as_posix(),
        poses=(worlds_dir() / "hand_poses.toml").as_posix(),
    )
    return write(tmp_path / "w.toml", head + body)


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (
            "[locations]\na = { pos = [0, 0], rpy = [0, 0, 0] }",
            "locations.a.pos: expected a list of 3",
        ),
        ("[locations]\na = { pos = [0, 0, 0] }", "locations.a: missing key 'rpy'"),
        (
            '[locations]\na = { object = "cup", pos = [0, 0, 0], rpy = [0, 0, 0] }',
            "locations.a.object: unknown object 'cup'; valid: block",
        ),
        (
            '[locations]\na = { pos = [0, 0, 0], rpy = [0, 0, 0], axes = "world" }',
            "locations.a.axes: axes applies to object-relative locations only",
        ),
        (
            '[locations]\na = { pos = [0, 0, "x"], rpy = [0, 0, 0] }',
            "locations.a.pos[2]: expected a number, got a string ('x')",
        ),
        (
            "[locations]\na = { pos = [0, 0, 0], rpy = [0, 0, 0] }\n"
            '[programs]\np = """\nMOVE a\nMOVE b\n"""',
            "programs.p line 2: unknown location 'b'; valid locations: a",
        ),
        (
            '[programs]\np = "JUMP 3"',
            "programs.p line 1: unknown command 'JUMP'; valid commands: MOVE",
        ),
        ('[programs]\np = "DRIVE 7 10"', "the PUMA has joints 1 to 6, not 7"),
        ('[programs]\np = "DEPART 5"', "distance 5 is out of range: expected -1 m to 1 m"),
        ('[programs]\np = "DEPART 3N"', "unit 'N' is not a length unit"),
        ('[programs]\np = "; nothing"', "programs.p: a program needs at least one statement"),
        (
            "[poses.p]\npinky = [0, 0, 0, 0]",
            "poses.p.pinky: unknown key; valid keys: index, middle",
        ),
        ("[poses.p]\nindex = { knuckle = 3 }", "valid keys: abd, mcp, pip, dip"),
        (
            "[poses.p]\nindex = [0, 0, 0, 200]",
            "poses.p.index.dip: 200 deg is beyond the dip joint's upper limit of 90 deg by 110 deg",
        ),
        ("[poses.p]", "poses.p: a pose must set at least one joint"),
        (
            '[criteria.c]\nkind = "best"',
            "criteria.c.kind: unknown criterion kind 'best'; valid: fraction",
        ),
        ('[criteria.c]\nkind = "plane_fit"\nset = "s"', "criteria.c: missing key 'object'"),
        (
            '[criteria.c]\nkind = "plane_fit"\nset = "s"\nobject = "block"\nface = "top"',
            "criteria.c.face: unknown face 'top'; valid: +x, -x",
        ),
        (
            '[criteria.c]\nkind = "fraction_in_region"\nbodies = "b*"\nregion = "r"\nmin = 2',
            "criteria.c: min must be a fraction in (0, 1]",
        ),
        (
            '[criteria.c]\nkind = "upright"\nobject = "block"\ntilt = 3',
            "criteria.c.tilt: unknown key",
        ),
        ("[bogus]", "bogus: unknown key; valid keys: scene, objects, robot, poses"),
        ("[thread]\nturns = true", "thread.turns: expected a number, got a boolean (true)"),
        ("[thread]", "thread: missing key 'turns' (keys: turns)"),
        ("[thread]\nturns = 2\npitch = 4", "thread.pitch: unknown key; valid keys: turns"),
        ('[thread]\nturns = "2"', "thread.turns: expected a number, got a string ('2')"),
        ("[thread]\nturns = 0", "thread.turns: expected more than 0 and at most 20, got 0"),
        ("[thread]\nturns = 25", "thread.turns: expected more than 0 and at most 20, got 25"),
        ("[locations]\n1a = { pos = [0, 0, 0], rpy = [0, 0, 0] }", "locations.1a: invalid name"),
    ],
)
def test_errors_name_file_key_and_choices(tmp_path: Path, body: str, message: str) -> None:
    path = _world(tmp_path, body)
    with pytest.raises(WorldFileError) as e:
        load_world(path)
    assert str(e.value).startswith(f"{path}: ")
    assert message in str(e.value)
    assert isinstance(e.value, ValueError)  # the SceneLoader contract


def test_thread_turns_are_a_world_setting_that_extends_inherits(tmp_path: Path) -> None:
    assert load_world(worlds_dir() / "lightbulb.toml").thread_turns == 1.5
    assert load_world(worlds_dir() / "lightbulb_long.toml").thread_turns == 3.5
    assert load_world(_world(tmp_path, "")).thread_turns is None  # the model's own range
    mine = write(tmp_path / "bulb.toml", 'extends = "lightbulb_long"\n[thread]\nturns = 5\n')
    world = load_world(mine)
    assert world.thread_turns == 5.0 and world.model_path.name == "scene_lightbulb.xml"


def test_false_drops_an_extended_criterion_and_true_is_an_error(tmp_path: Path) -> None:
    base = [c.name for c in load_world(resolve_scene("pour", tmp_path)).criteria]
    assert base == ["contents_in_cup", "pitcher_upright"]
    dropped = write(tmp_path / "a.toml", 'extends = "pour"\n[criteria]\ncontents_in_cup = false\n')
    assert [c.name for c in load_world(dropped).criteria] == ["pitcher_upright"]
    kept = write(tmp_path / "b.toml", 'extends = "pour"\n[criteria]\ncontents_in_cup = true\n')
    message = r"b.toml: criteria.contents_in_cup: expected a table, or false to drop an extended"
    with pytest.raises(WorldFileError, match=message):
        load_world(kept)


def test_toml_syntax_error_names_the_file(tmp_path: Path) -> None:
    path = write(tmp_path / "bad.toml", "[scene\n")
    with pytest.raises(WorldFileError, match=r"bad.toml: invalid TOML: .*line 1"):
        load_world(path)


def test_a_world_pose_replaces_the_shared_one_of_that_name(tmp_path: Path) -> None:
    shared = load_world(_world(tmp_path, "")).poses["prelight"]
    mine = load_world(_world(tmp_path, "[poses.prelight]\nthumb = { abd = 7 }"))
    assert mine.poses["prelight"].mask == 0x1000 != shared.mask
    assert mine.poses["prelight"].angles[12] == pytest.approx(math.radians(7))
    # The light-bulb task keeps the paper's names, with its own values.
    bulb = load_world(worlds_dir() / "lightbulb.toml")
    assert bulb.poses["unscrew"].mask == 0x1010 and shared.mask == 0xFFFF


def test_missing_model_and_pose_file(tmp_path: Path) -> None:
    path = write(tmp_path / "w.toml", '[scene]\nmodel = "nope.xml"\n[objects]\na = "b"\n')
    with pytest.raises(WorldFileError, match=r"scene.model: no such model file: .*nope.xml"):
        load_world(path)
    path = _world(tmp_path, "").read_text().replace("hand_poses.toml", "gone.toml")
    with pytest.raises(WorldFileError, match=r"w.toml: no such file: .*gone.toml"):
        load_world(write(tmp_path / "w.toml", path))


def test_extends_a_bundled_scene_by_name_and_detects_cycles(tmp_path: Path) -> None:
    mine = write(
        tmp_path / "mine.toml",
        'extends = "containment"\n[objects]\ntarget = "containment_rounded"\n',
    )
    world = load_world(mine)
    assert world.name == "mine" and world.locations["side_135"].body == "containment_rounded"
    programs = {"to_top", "down_top", "to_sides", "down_sides", "to_top_again", "leave_top"}
    programs |= {f"to_top_{side}" for side in ("east", "west", "north", "south")}
    programs |= {f"next_{azimuth}" for azimuth in (270, 0, 90, 135)}
    programs |= {f"back_{azimuth}" for azimuth in (45, 315, 225)}
    assert load_scene_names("mine.toml", tmp_path).programs == programs
    write(tmp_path / "a.toml", 'extends = "b.toml"\n')
    write(tmp_path / "b.toml", 'extends = "a.toml"\n')
    with pytest.raises(WorldFileError, match=r"extends cycle: .*a.toml -> .*b.toml -> .*a.toml"):
        load_world(tmp_path / "a.toml")
    write(tmp_path / "c.toml", 'extends = "nowhere"\n')
    with pytest.raises(WorldFileError, match=r"c.toml: extends: unknown scene 'nowhere'"):
        load_world(tmp_path / "c.toml")


def test_extends_a_list_merges_the_bases_in_order(tmp_path: Path) -> None:
    lib = tmp_path / "lib"
    lib.mkdir()
    write(
        lib / "a.toml", '[locations]\na = { object = "block", pos = [0, 0, 0.1], rpy = [0, 0, 0] }'
    )
    write(lib / "b.toml", '[programs]\nup = "MOVES a"\nback = "DEPART 0.1"')
    base = _world(tmp_path, "")
    mine = write(tmp_path / "mine.toml", f'extends = ["{base.name}", "lib/a.toml", "lib/b.toml"]\n')
    world = load_world(mine)
    assert world.model_path.name == "scene_surface.xml"
    assert world.locations["a"].body == "surface_block"
    assert set(world.programs) == {"up", "back"}


def test_extends_a_list_rejects_a_name_two_bases_define_differently(tmp_path: Path) -> None:
    base = _world(tmp_path, "").name
    write(tmp_path / "p.toml", '[programs]\nback = "DEPART 0.1"')
    write(tmp_path / "q.toml", '[programs]\nback = "DEPART 0.2"')
    write(tmp_path / "same.toml", '[programs]\nback = "DEPART 0.1"')
    clash = write(tmp_path / "clash.toml", f'extends = ["{base}", "p.toml", "q.toml"]\n')
    with pytest.raises(
        WorldFileError,
        match=r"clash.toml: programs.back: set differently by p.toml and q.toml; set it in this",
    ):
        load_world(clash)
    # The same definition twice is no conflict, and the child may settle one.
    load_world(write(tmp_path / "ok.toml", f'extends = ["{base}", "p.toml", "same.toml"]\n'))
    chosen = write(
        tmp_path / "chosen.toml",
        f'extends = ["{base}", "p.toml", "q.toml"]\n[programs]\nback = "DEPART 0.3"\n',
    )
    assert load_world(chosen).programs["back"].statements == (Depart(1, 0.3),)
    # A base that extends an earlier one refines it: no conflict, the later one wins.
    write(tmp_path / "r.toml", 'extends = "p.toml"\n[programs]\nback = "DEPART 0.4"')
    refined = write(tmp_path / "refined.toml", f'extends = ["{base}", "p.toml", "r.toml"]\n')
    assert load_world(refined).programs["back"].statements == (Depart(1, 0.4),)
    # Descriptions are only text.
    write(tmp_path / "d1.toml", '[scene]\ndescription = "one"')
    write(tmp_path / "d2.toml", '[scene]\ndescription = "two"')
    load_world(write(tmp_path / "ds.toml", f'extends = ["{base}", "d1.toml", "d2.toml"]\n'))
    for bad in ("[]", "3", '["p.toml", 3]'):
        path = write(tmp_path / "bad.toml", f"extends = {bad}\n")
        with pytest.raises(WorldFileError, match="extends: expected a world file"):
            load_world(path)


def test_a_redefined_location_replaces_the_whole_entry(tmp_path: Path) -> None:
    # A world-frame location in the child does not keep the object of the base's location.
    base = _world(
        tmp_path, '[locations]\na = { object = "block", pos = [0, 0, 0.1], rpy = [0, 0, 0] }'
    )
    child = write(
        tmp_path / "child.toml",
        f'extends = "{base.name}"\n[locations]\na = {{ pos = [0.5, 0, 0.6], rpy = [180, 0, 0] }}\n',
    )
    assert load_world(child).locations["a"].body is None


def test_explore_worlds_define_every_name_of_both_procedures() -> None:
    block = load_world(worlds_dir() / "explore_block.toml")
    cylinder = load_world(worlds_dir() / "explore_cylinder.toml")
    for world in (block, cylinder):
        names = world.scene_names()
        assert {"to_probe", "to_south", "to_sides", "next_135", "leave_north"} <= names.programs
        assert {"trace_point", "probe", "top"} <= set(names.poses)
        assert world.objects["block"] == world.objects["target"]
    assert (
        block.objects["target"] == "surface_block" and block.model_path.name == "scene_surface.xml"
    )
    assert [c.name for c in block.criteria] == ["top_plane"]
    assert cylinder.objects["target"] == "containment_cylinder"
    assert [c.name for c in cylinder.criteria] == ["shape_fit"]


def test_parsing_does_not_import_mujoco() -> None:
    code = (
        "import sys, dial.scene; dial.scene.load_scene_names('pour', __import__('pathlib').Path())"
    )
    code += "; assert 'mujoco' not in sys.modules, 'dial.scene imported mujoco'"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
