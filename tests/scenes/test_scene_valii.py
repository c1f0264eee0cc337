"""The VAL-II subset of arm programs."""

from __future__ import annotations

import math

import pytest

from dial.scene import Appro, Depart, Drive, Move, StatementError, parse_statement


@pytest.mark.parametrize(
    ("text", "statement"),
    [
        ("MOVE home", Move(1, "home", straight=False)),
        ("moves above_bulb   ; comment", Move(1, "above_bulb", straight=True)),
        ("APPRO above_bulb 0.1", Appro(1, "above_bulb", 0.1)),
        ("appro above_bulb, 100mm", Appro(1, "above_bulb", pytest.approx(0.1))),
        ("DEPART -5cm", Depart(1, pytest.approx(-0.05))),
        ("DRIVE 6, -90", Drive(1, 6, pytest.approx(-math.pi / 2))),
        ("DRIVE 1 0.5rad", Drive(1, 1, 0.5)),
        ("   ; only a comment", None),
        ("", None),
    ],
)
def test_statements(text: str, statement: object) -> None:
    assert parse_statement(text) == statement


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("GOTO home", "unknown command 'GOTO'; valid commands: MOVE, MOVES, APPRO, DEPART, DRIVE"),
        ("MOVE", "expected 'MOVE LOCATION', got 'MOVE'"),
        ("APPRO home", "expected 'APPRO LOCATION DISTANCE', got 'APPRO home'"),
        ("MOVE 9lives", "expected a location name"),
        ("APPRO home -0.1", "distance -0.1 is out of range: expected 0 m to 1 m"),
        ("DRIVE 0 10", "expected an arm joint number from 1 to 9, got '0'"),
        ("DRIVE 6 400", "angle 400 is out of range: expected -360 deg to 360 deg"),
        ("DRIVE 6 ten", "expected an angle in deg"),
    ],
)
def test_statement_errors(text: str, message: str) -> None:
    with pytest.raises(StatementError) as e:
        parse_statement(text)
    assert message in str(e.value)
