"""``dial preview`` from Python: what it checks, where it reports, how it walks a timeline."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dial.api import load
from dial.backend.driver import CONTROL_PERIOD
from dial.engine.setup import script_world
from dial.geometry import location_pose
from dial.instructions.grasp_force import GraspForceArgs
from dial.preview import preview
from dial.preview.motions import grasp
from dial.preview.places import statement_place
from dial.preview.scene import Scene
from dial.preview.walk import Walk
from dial.scene import worlds_dir

# A world on the surface scene with a program whose DRIVE passes joint 1's limit (160 deg).
# (A pose beyond a joint's range is refused when the world file loads, at check time.)
EDGE_WORLD = """\
extends = "surface"

[programs]
drive_far = \"\"\"
MOVE above_block
DRIVE 1 170
\"\"\"
"""

EDGE = """\
@scene edge.toml
@tick 0.1
% to     puma_command "ex to_block"
% far    arm_move     0 0 0.9 frame=world
% down   arm_move     0 0 -0.25 frame=world
% drive  puma_command "ex drive_far"
% touch  tactile_contact finger=index
% back   puma_command "ex to_block"

to     #====
far          #
down          #=
@if touch
drive  #===
@else
back   #===
@end
"""


def line_of(text: str, start: str) -> int:
    """The 1-based line of ``text`` that starts with ``start``."""
    return next(i for i, line in enumerate(text.splitlines(), 1) if line.startswith(start))


@pytest.fixture(scope="module")
def edge(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str], list[str]]:
    folder = tmp_path_factory.mktemp("edge")
    (folder / "edge.toml").write_text(EDGE_WORLD)
    script = folder / "edge.dial"
    script.write_text(EDGE)
    result = preview(load(script))
    return script, result.problems, result.notes


def test_pour_previews_clean() -> None:
    result = preview(load("pour.dial"))
    assert result.ok and result.problems == [] and result.notes == []
    assert result.summary() == (
        "pour.dial: preview OK: 15 blocks, 21 arm targets, 6 hand targets"
        " (2 @on reactions, 7 loops once each)"
    )


def test_a_location_out_of_reach_is_named_at_the_line_that_uses_it(tmp_path: Path) -> None:
    (tmp_path / "far.toml").write_text(
        'extends = "pour"\n[locations]\n'
        'lid_grasp = { object = "lid", pos = [1.9, 0, 0.121], rpy = [0, 180, 0] }\n'
    )
    script = load("pour.dial", scene=str(tmp_path / "far.toml"))
    result = preview(script)
    text = Path(script.path).read_text()
    run = f"{script.path}:{line_of(text, 'get_top  ')}:13: get_top: "
    assert not result.ok
    appro = f"{run}APPRO lid_grasp (program get_top line 1, pour.toml:"
    assert result.problems[0].startswith(appro)
    assert result.problems[1].startswith(f"{run}location 'lid_grasp' (program get_top line 2, ")
    assert "is out of the arm's reach: the tool stays" in result.problems[1]


def test_program_statements_are_placed_in_their_world_file(tmp_path: Path) -> None:
    pour = worlds_dir() / "pour.toml"
    lines = pour.read_text().splitlines()
    place = statement_place(pour, "get_top", 2)
    assert place is not None and place.startswith("pour.toml:")
    assert lines[int(place.split(":")[1]) - 1].startswith("MOVES lid_grasp")
    (tmp_path / "child.toml").write_text(f'extends = "{pour}"\n[programs]\nmine = "DEPART 0.1"\n')
    assert statement_place(tmp_path / "child.toml", "mine", 1) == "child.toml:3"
    assert statement_place(tmp_path / "child.toml", "lift_top", 3) == (
        f"pour.toml:{line_of(pour.read_text(), 'MOVES lid_drop')}"
    )


def test_joint_limits_reach_and_collisions_are_reported_at_their_runs(
    edge: tuple[Path, list[str], list[str]],
) -> None:
    script, problems, _ = edge
    at = {name: f"{script}:{line_of(EDGE, name + ' ')}:" for name in ("far", "down")}
    assert any(
        p.startswith(f"{at['far']}14: far: the arm_move goal is out of the arm's reach")
        for p in problems
    )
    down = [p for p in problems if p.startswith(f"{at['down']}15: down: ")]
    assert any("the palm presses into surface_table" in p for p in down), down
    assert any("the arm hits surface_block" in p for p in down), down
    assert all(" mm deep" in p for p in down)


def test_a_branch_not_taken_gives_notes(edge: tuple[Path, list[str], list[str]]) -> None:
    script, problems, notes = edge
    # 'down' takes the hand through the block and the table top: the fingers end under the
    # table, touching nothing, so 'touch' does not hold and the @if's branch is not taken.
    drive = f"{script}:{line_of(EDGE, 'drive  #')}:8: note: drive: DRIVE 1 170 (program "
    assert not any("DRIVE" in p for p in problems)
    assert len(notes) == 1 and notes[0].startswith(drive)
    assert f"edge.toml:{line_of(EDGE_WORLD, 'DRIVE')}): the target 185.8 deg is" in notes[0]
    why = f"; the @if touch of edge.dial:{line_of(EDGE, '@if')} is previewed false"
    assert notes[0].endswith(why)


def walk(script_arg: str, scene: str | None = None) -> Walk:
    script = load(script_arg, scene=scene)
    walk = Walk(Scene(script_world(script)), round((script.tick or 0.25) / CONTROL_PERIOD))
    walk.steps(script, script.timeline, "")
    return walk


def test_a_grasped_object_is_carried_until_the_hand_opens() -> None:
    done = walk("pour.dial")
    scene = done.scene
    world, believed = scene.world, scene.ctx.believed
    lid = scene.model.body("pour_lid").id
    pitcher = scene.model.body("pour_pitcher").id
    ball = scene.model.body("pour_ball_00").id
    start = {b: believed[scene.model.body(b).name][0] for b in (lid, pitcher)}
    # The lid was put down where the arm released it, 10.5 cm below lid_over_drop...
    drop = location_pose(world, believed, "lid_drop")[0]
    assert np.linalg.norm(scene.data.xpos[lid][:2] - drop[:2]) < 0.01
    assert np.linalg.norm(scene.data.xpos[lid] - start[lid]) > 0.2
    # ... and the pitcher, with its balls, set back where it was taken from.
    assert np.linalg.norm(scene.data.xpos[pitcher] - start[pitcher]) < 0.005
    assert scene.held == ()
    assert 0.35 < scene.data.xpos[ball][2] < 0.45
    assert done.latest[(done.panels[0].place.rsplit(":", 1)[0], "grabpit")].value == "done"


def test_a_guarded_move_stops_at_the_first_touch_and_chooses_the_branch() -> None:
    done = walk("explore.dial")
    path = str(Path(load("explore.dial").path))
    # find touched the block's top (done), so '@if !find' goes to its @else; wide touched too.
    assert done.latest[(path, "find")].value == "done"
    assert done.latest[(path, "wide")].value == "done"
    labels = [p.label for p in done.panels]
    assert any(label.startswith("@if !find (not taken)") for label in labels)
    assert any("@call explore_surface.dial" in label for label in labels)
    assert any("@call containment.dial" in label and "(not taken)" in label for label in labels)
    # The index pad rests on the top face at its end: no deeper than the bisection's step.
    assert done.problems.count == 0


def test_a_monitor_preempts_its_block_and_its_reaction_is_previewed() -> None:
    done = walk("reactions.dial")
    down, reaction = done.panels[1], done.panels[2]
    assert down.events == ("down",)
    assert down.note == "preempted: @on touch fired"
    assert reaction.label.startswith("@on touch (line ")
    assert done.counts.reactions == 1 and done.problems.count == 0


def test_fingers_that_collide_are_reported(tmp_path: Path) -> None:
    # lightbulb.toml's unscrew pose abducts the middle finger 15 deg towards the index. With
    # the index curled in, as the bulb's preshape had it before issue 13, the index stays in
    # the way: the two overlap (in the run too: they pressed on each other). With every
    # finger bent back straight, as the preshape is now, they pass.
    assert not preview(load("lightbulb.dial")).problems
    curled = tmp_path / "curled.toml"
    fingers = "".join(f"{f} = [0, -15, 20, 20]\n" for f in ("index", "middle", "ring", "thumb"))
    curled.write_text(f'extends = "lightbulb"\n\n[poses.prelight]\n{fingers}')
    result = preview(load("lightbulb.dial", scene=str(curled)))
    assert result.problems
    assert all("the index finger and the middle finger collide" in p for p in result.problems)
    assert all(": twist_hand: " in p for p in result.problems)


def test_a_grasp_holds_what_its_fingers_touch_and_what_lies_inside_it() -> None:
    script = load("pour.dial")
    scene = Scene(script_world(script))
    ctx, robot = scene.ctx, scene.robot
    pos, rot = ctx.location("pitcher_grasp")
    robot.arm_target = ctx.arm_ik.solve(pos, rot, robot.arm_target, "pitcher_grasp")
    for bit, angle in ctx.world.poses["prepit"].angles.items():
        robot.hand_target[bit] = angle
    scene.pose()
    args = script.events["grabpit"].args
    assert isinstance(args, GraspForceArgs)
    report = grasp(scene, lambda: None, args.jmask, args.tmask)
    assert report.outcome.value == "done"
    (grip,) = scene.held
    names = {scene.model.body(b).name for b in grip.bodies}
    balls = {n for n in names if n.startswith("pour_ball_")}
    every_ball = {
        scene.model.body(b).name
        for b in range(scene.model.nbody)
        if scene.model.body(b).name.startswith("pour_ball_")
    }
    assert "pour_pitcher" in names and balls == every_ball and "pour_cup" not in names
    assert grip.fingers == {1, 3}  # middle and thumb
    # Lifted 10 cm, everything held goes up 10 cm with the hand.
    ball = scene.model.body("pour_ball_07").id
    before = scene.data.xpos[ball].copy()
    robot.arm_target = ctx.arm_ik.solve(pos + np.array([0, 0, 0.1]), rot, robot.arm_target, "up")
    scene.pose()
    assert np.allclose(scene.data.xpos[ball] - before, [0, 0, 0.1], atol=0.003)
