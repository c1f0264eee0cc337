"""Every instruction of the catalogue names the primitive class that runs it."""

from __future__ import annotations

from dial.instructions import INSTRUCTIONS
from dial.primitives import CLASSES
from dial.scheduler.types import Primitive


def test_every_instruction_names_a_primitive_class() -> None:
    for name, instruction in INSTRUCTIONS.items():
        assert instruction.primitive in CLASSES, name
    assert set(CLASSES) == {i.primitive for i in INSTRUCTIONS.values()}  # and none is spare


def test_zero_length_instructions_are_sensors_and_the_rest_primitives() -> None:
    for name, instruction in INSTRUCTIONS.items():
        cls = CLASSES[instruction.primitive]
        if instruction.length == "zero":
            assert hasattr(cls, "sense") and not issubclass(cls, Primitive), name
        else:
            assert issubclass(cls, Primitive), name


def test_watchable_instructions_are_the_contact_conditions() -> None:
    watchable = {n for n, i in INSTRUCTIONS.items() if i.condition is not None}
    assert watchable == {"position_contact", "force_contact", "tactile_contact"}
