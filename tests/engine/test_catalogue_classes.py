"""Every instruction is declared once: its record makes its primitive or sensor, and says how
the preview moves it, with nothing looked up by the instruction's name."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from dial.instructions import INSTRUCTIONS
from dial.instructions.base import Args
from dial.parser import check_text
from dial.preview.moves import AtOnce, Sensed, Stepped
from dial.preview.scene import Scene
from dial.primitives.context import Context
from dial.scene import load_scene_names
from dial.scene.of_script import script_world
from dial.scheduler.primitive import Allotment, Primitive

from ..conftest import ROOT

# One event of every instruction (every verb of puma_command), in the pour scene.
EVENTS = {
    "get_joints": "get_joints",
    "get_forces": "get_forces",
    "get_tactile": "get_tactile",
    "get_wrist": "get_wrist",
    "hand_pose": 'hand_pose "prepit"',
    "finger_move": "finger_move finger=index 0 0 0.01",
    "puma_command": 'puma_command "ex get_top"',
    "puma_move": 'puma_command "moves lid_grasp"',
    "puma_appro": 'puma_command "appro lid_grasp 0.1"',
    "puma_depart": 'puma_command "depart 0.05"',
    "puma_drive": 'puma_command "drive 2 10"',
    "arm_move": "arm_move 0 0 0.01",
    "position_contact": "position_contact finger=index",
    "force_contact": "force_contact finger=thumb",
    "tactile_contact": "tactile_contact finger=middle",
    "grasp_force": 'grasp_force "0x0666_0x0222 4.0"',
    "guarded_move": "guarded_move 0 0 -0.05 until=tactile",
    "limp": "limp",
    "record_contact": "record_contact finger=index",
    "locate": 'locate "lid_grasp"',
    "fit_plane": "fit_plane",
    "fit_superquadric": "fit_superquadric",
}


@pytest.fixture(scope="module")
def events() -> dict[str, Args]:
    text = "@scene pour\n" + "".join(f"% {name} {d}\n" for name, d in EVENTS.items())
    script = check_text(text + "get_joints #\n", "all.dial", loader=load_scene_names)
    assert {e.instruction.name for e in script.events.values()} == set(INSTRUCTIONS)
    return {name: event.args for name, event in script.events.items()}


@pytest.fixture(scope="module")
def ctx() -> Context:
    script = check_text("@scene pour\n% a get_joints\na #\n", "s.dial", loader=load_scene_names)
    return Scene(script_world(script), textures=False).ctx


def test_each_record_makes_its_primitive_or_sensor(events: dict[str, Args], ctx: Context) -> None:
    for name, args in events.items():
        length = INSTRUCTIONS[EVENTS[name].split()[0]].length
        if length == "zero":
            assert hasattr(args.sensor(ctx), "sense"), name
            with pytest.raises(NotImplementedError):
                args.primitive(ctx, Allotment(frozenset(), 10, 10, 0.01))
        else:
            allotted = Allotment(args.effectors(None), 10, 10, 0.01)
            assert isinstance(args.primitive(ctx, allotted), Primitive), name


def test_each_record_says_how_the_preview_moves_it(events: dict[str, Args]) -> None:
    kinds = {name: type(args.preview()) for name, args in events.items()}
    for name, kind in kinds.items():
        length = INSTRUCTIONS[EVENTS[name].split()[0]].length
        expected = {"zero": Sensed, "fixed": Stepped, "indeterminate": AtOnce}[length]
        if name.endswith("_contact"):  # a contact wait is sensed from the pose
            expected = Sensed
        assert kind is expected, name


def test_a_condition_only_contact_event_is_a_sensor(events: dict[str, Args], ctx: Context) -> None:
    for name in ("position_contact", "force_contact", "tactile_contact"):
        assert hasattr(events[name].sensor(ctx), "sense")
        assert events[name].contact() is not None
    assert all(args.contact() is None for n, args in events.items() if "_contact" not in n)


def test_watchable_instructions_are_the_contact_conditions() -> None:
    watchable = {n for n, i in INSTRUCTIONS.items() if i.condition is not None}
    assert watchable == {"position_contact", "force_contact", "tactile_contact"}


def _names_compared(path: Path) -> list[str]:
    """Instruction names that ``path`` compares something with (``== "limp"``, ``in (...)``)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Compare):
            for const in ast.walk(node):
                if isinstance(const, ast.Constant) and const.value in INSTRUCTIONS:
                    found.append(f"{path.name}:{const.lineno} {const.value!r}")
    return found


def test_nothing_outside_an_instructions_own_module_names_it() -> None:
    # The run (scheduler, primitives, robot, backend, engine) and the preview never find an
    # instruction's class or behaviour by its name.
    places = ("scheduler", "primitives", "robot", "backend", "engine", "preview")
    found = [
        hit for place in places for path in (ROOT / "dial" / place).rglob("*.py")
        for hit in _names_compared(path)
    ]  # fmt: skip
    assert found == []
