"""Quantities, masks and the other parameter types."""

from __future__ import annotations

import math

import pytest

from dial.instructions.types import (
    Conditions,
    Finger,
    MaskPair,
    ParamError,
    Quantity,
    mask_fingers,
    parse_mask,
)
from dial.units import UnitError, parse_quantity


@pytest.mark.parametrize(
    ("text", "dim", "unit", "value"),
    [
        ("10deg", "angle", "rad", math.radians(10)),
        ("0.5", "angle", "rad", 0.5),
        ("30", "angle", "deg", math.radians(30)),
        ("5mm", "length", "m", 0.005),
        ("-2.5cm", "length", "m", -0.025),
        ("2N", "force", "N", 2.0),
        ("300ms", "time", "s", 0.3),
        ("1e-3", "time", "s", 0.001),
        ("20mm/s", "speed", "m/s", 0.02),
    ],
)
def test_quantities_convert_to_si(text: str, dim: str, unit: str, value: float) -> None:
    assert parse_quantity(text, dim, unit) == pytest.approx(value)  # type: ignore[arg-type]


@pytest.mark.parametrize("text", ["", "mm", "1.2.3", "1e999", "nan", "5 mm", "0x10"])
def test_malformed_quantities_are_rejected(text: str) -> None:
    with pytest.raises(UnitError):
        parse_quantity(text, "length", "m")


def test_wrong_dimension_names_the_expected_units() -> None:
    with pytest.raises(UnitError, match=r"expected a force in N \(or mN\)"):
        parse_quantity("4mm", "force", "N")


def test_quantity_range_is_inclusive_unless_open() -> None:
    q = Quantity("force", "N", 0.0, 40.0, lo_open=True)
    assert q.parse("40N") == 40.0
    with pytest.raises(ParamError, match="above 0 N to 40 N"):
        q.parse("0")


def test_paper_mask_pair() -> None:
    # Close joints 1-2 of index, middle and ring; watch joint 1 of each (DESIGN 3).
    assert MaskPair().parse("0x0666_0x0222") == (0x0666, 0x0222)
    assert mask_fingers(0x0666) == {"index", "middle", "ring"}
    assert mask_fingers(0xF000) == {"thumb"}


@pytest.mark.parametrize("text", ["0x0666", "0x0666_", "0x0666_0x1000", "0_0x0001", "x_y"])
def test_bad_mask_pairs(text: str) -> None:
    with pytest.raises(ParamError):
        MaskPair().parse(text)


@pytest.mark.parametrize(
    ("text", "mask"), [("0x0666", 0x0666), ("0X00_0F", 0x000F), ("00666", 666), ("0x_1", 1)]
)
def test_masks_in_hex_or_decimal(text: str, mask: int) -> None:
    assert parse_mask(text) == mask


@pytest.mark.parametrize("text", ["0x", "0x__", "0x1g", "-1", "0x10000", "0"])
def test_bad_masks_are_parameter_errors(text: str) -> None:
    # A mutated script once reached int("00666", 0), which raised a bare ValueError.
    with pytest.raises(ParamError):
        parse_mask(text)


def test_fingers_by_name_or_number() -> None:
    assert [Finger().parse(t) for t in ("index", "1", "ring", "3")] == [0, 1, 2, 3]
    with pytest.raises(ParamError, match="index, middle, ring or thumb"):
        Finger().parse("4")


def test_contact_conditions_with_thresholds() -> None:
    assert Conditions().parse("tactile:0.1mm,position:2mm") == (
        ("tactile", pytest.approx(0.0001)),
        ("position", pytest.approx(0.002)),
    )
    assert Conditions().parse("force")[0][0] == "force"
    with pytest.raises(ParamError, match="given twice"):
        Conditions().parse("force,force")
