"""A teaching session on the surface scene: motions, refusals that change nothing, saving, undo."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from dial.geometry import location_pose
from dial.teach.commands import parse_command
from dial.teach.session import Session, TeachError
from dial.teach.sim import Sim
from dial.teach.target import open_target


@pytest.fixture
def session(tmp_path: Path) -> Session:
    world, target = open_target("surface", str(tmp_path / "taught.toml"), tmp_path)
    return Session(world, target, Sim(world))


def run(session: Session, line: str) -> str:
    command = parse_command(line)
    assert command is not None
    return session.execute(command, line).text


def refused(session: Session, line: str) -> str:
    """The error of a command that must change nothing (the physics state is compared)."""
    before = session.sim.state()
    with pytest.raises(TeachError) as e:
        run(session, line)
    after = session.sim.state()
    assert np.array_equal(before.physics, after.physics)
    assert np.array_equal(before.arm_target, after.arm_target)
    assert np.array_equal(before.hand_target, after.hand_target)
    return str(e.value)


def test_a_jog_moves_the_tool_exactly_by_the_step(session: Session) -> None:
    p0 = session.goal[0].copy()
    run(session, "goto above_block")
    start = session.goal[0].copy()
    assert not np.allclose(start, p0)
    run(session, "jog 10 -20 30")
    assert session.goal[0] == pytest.approx(start + np.array([0.01, -0.02, 0.03]), abs=1e-12)
    assert np.linalg.norm(session.sim.tool()[0] - session.goal[0]) < 1e-3  # within the IK's 0.5 mm
    run(session, "jog tool z 10")  # the tool points down: tool +z is world -z
    assert session.goal[0] == pytest.approx(start + np.array([0.01, -0.02, 0.02]), abs=1e-9)


def test_out_of_reach_leaves_the_robot_where_it_was(session: Session) -> None:
    message = refused(session, "jog x 2000")
    assert "out of the arm's reach" in message and "the robot stays where it was" in message


def test_a_collision_is_undone_and_named(session: Session) -> None:
    run(session, "goto above_block")
    message = refused(session, "jog z -200")
    assert "refused:" in message and "into surface_block" in message


def test_a_joint_beyond_its_range_is_refused(session: Session) -> None:
    assert "PUMA joint 2 would go to" in refused(session, "drive 2 300")
    assert "thumb pip would go to 150.0 deg, beyond its range" in refused(
        session, "finger thumb 0 0 150 0"
    )


def test_unknown_names_list_the_valid_ones(session: Session) -> None:
    message = refused(session, "goto nowhere")
    assert "unknown location 'nowhere'; locations: trace_south" in message
    assert "above_block" in message
    assert "unknown program 'dance'; programs: retract_arm" in refused(session, "ex dance")
    assert "unknown pose 'claw'; poses: open_hand, spread" in refused(session, "pose claw")
    message = refused(session, "save location x relative-to table")
    assert "unknown object 'table'; objects: block" in message


def test_fingers_move_limp_and_are_saved_as_measured(session: Session) -> None:
    run(session, "finger index 0 30 20 10")
    answer = run(session, "limp index for=0.2s")
    assert answer.startswith("index   abd")
    q = session.sim.hand_q()
    assert q[1] == pytest.approx(math.radians(30), abs=math.radians(1))
    assert not session.sim.limp.any()  # limp ends holding where the joints came to rest
    run(session, "save pose bent fingers=0x000F")
    pose = session.world.poses["bent"]
    assert pose.mask == 0x000F
    assert pose.angles[1] == pytest.approx(q[1], abs=math.radians(0.06))


def test_a_saved_location_gives_back_the_tool_pose(session: Session) -> None:
    run(session, "goto above_block")
    run(session, "jog 0 30 -20 0 0 15")
    run(session, "save location side relative-to block")
    run(session, "save location side_world")
    for name in ("side", "side_world"):
        pos, rot = location_pose(session.world, session.sim.ctx.believed, name)
        # Rounded to 0.1 mm, and relative to where the block is now (it settled 0.1 mm since
        # the world model's belief at load).
        assert pos == pytest.approx(session.goal[0], abs=3e-4)
        assert np.abs(rot - session.goal[1]).max() < 2e-3  # and 0.1 deg
    run(session, "jog z 20")
    run(session, "goto side")  # a saved name is usable at once
    side = location_pose(session.world, session.sim.ctx.believed, "side")
    assert session.goal[0] == pytest.approx(side[0])


def test_undo_goes_back_one_command_at_a_time(session: Session) -> None:
    start = session.sim.state()
    run(session, "jog z -30")
    after_jog = session.sim.state()
    run(session, "save location low")
    assert run(session, "undo") == "undid 'save location low'"
    assert "low" not in session.world.locations and not session.saved
    assert np.array_equal(session.sim.state().physics, after_jog.physics)
    run(session, "undo")
    assert np.array_equal(session.sim.state().physics, start.physics)
    with pytest.raises(TeachError, match="nothing to undo"):
        run(session, "undo")


def test_quit_asks_for_a_write_first(session: Session) -> None:
    run(session, "save location here")
    with pytest.raises(TeachError, match=r"1 saved name \(here\) not written to taught.toml"):
        run(session, "quit")
    reply = session.execute(parse_command("quit!"), "quit!")  # type: ignore[arg-type]
    assert reply.quit


def test_where_lists_contacts(session: Session) -> None:
    run(session, "goto above_block")
    assert "contacts: none" in run(session, "where")
    run(session, "pose point")
    run(session, "jog z -20")  # the index tip onto the block's top
    where = run(session, "where")
    assert "contacts:\n  hand_index_distal - surface_block (surface_block)" in where


def test_tab_completion_offers_commands_and_the_scenes_names(session: Session) -> None:
    from dial.teach.repl import completions

    words = completions(session)
    for word in ("jog", "save", "relative-to", "above_block", "to_block", "block", "thumb"):
        assert word in words
    run(session, "save location fresh")
    assert "fresh" in completions(session)  # a saved name completes at once
