"""Faults on purpose (DESIGN 2.8): ``--disturb`` pushes and sensor dropouts."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import dial
from dial.cli import main
from dial.disturb import Dropout, Push, parse_disturbance
from dial.errors import OptionError


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("", "expected 'push' or 'sense', got nothing"),
        ("shove body=x", "expected 'push' or 'sense', got 'shove'"),
        ("push body=x force=1,0 at=0 for=1", "force=1,0: expected three components"),
        ("push body=x force=1,0,0 at=0", "missing for="),
        ("push body=x force=1,0,0 at=-1 for=1", "at= must be 0 s or more, got -1"),
        ("push body=x force=1,0,0 at=0 for=0", "for= must be above 0 s, got 0"),
        ("push body=x force=1N,0,2kg at=0 for=1", "unit 'kg' is not a force unit"),
        ("push body=x force=9999,0,0 at=0 for=1", "is above 1000 N in magnitude"),
        ("push body=x force=1,0,0 at=0 for=1 speed=3", "unknown key 'speed='"),
        ("push body=x body=y force=1,0,0 at=0 for=1", "'body=' is given twice"),
        ("sense sensor=tactile at=1", "expected KIND:FINGER"),
        ("sense sensor=smell:index at=1", "expected KIND:FINGER"),
        ("sense sensor=force:index", "missing at="),
        ("push body=x force=nan,0,0 at=0 for=1", "expected a force"),
    ],
)
def test_a_bad_spec_says_what_was_expected(spec: str, message: str) -> None:
    with pytest.raises(OptionError) as caught:
        parse_disturbance(spec)
    assert message in str(caught.value) and str(caught.value).startswith(f"--disturb '{spec}'")


def test_specs_parse_with_units() -> None:
    push = parse_disturbance("push body=pour_pitcher force=3N,0,-500mN at=300ms for=0.1")
    assert push == Push("pour_pitcher", (3.0, 0.0, -0.5), 0.3, 0.1, push.text)
    drop = parse_disturbance("sense sensor=tactile:thumb at=2")
    assert drop == Dropout("tactile", 3, 2.0, None, drop.text) and drop.until is None


@pytest.mark.parametrize(
    ("spec", "listing"),
    [
        ("push body=nosuch force=1,0,0 at=0.5 for=0.1", "valid bodies: hand_base, "),
        ("sense sensor=tactile:pinky at=1", "FINGER one of index, middle, ring, thumb"),
    ],
)
def test_unknown_names_are_usage_errors_before_anything_moves(
    spec: str, listing: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    log = tmp_path / "log.jsonl"
    assert main(["run", "reactions.dial", "--disturb", spec, "--log", str(log), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert listing in err and err.count("\n") == 1
    assert not log.exists() or log.read_text() == ""  # nothing ran, not even the scene


def test_a_push_is_logged_where_it_begins_and_ends(tmp_path: Path) -> None:
    spec = "push body=puma_link6 force=0,0,-40 at=0.2 for=0.1"
    log = tmp_path / "log.jsonl"
    result = dial.run("reactions.dial", disturb=[spec], log=log)
    records = [json.loads(line) for line in log.read_text().splitlines()]
    phases = [(r["phase"], r["t"], r["step"], r["tick"]) for r in records if r["kind"] == "disturb"]
    assert phases == [("begin", 0.2, 100, 3), ("end", 0.3, 150, 4)]
    assert records[-1]["disturbances"] == [spec] and result.disturbances == (spec,)
    # A 40 N push down on the wrist for 0.1 s moves the arm: the run is not the undisturbed one.
    assert result.final_qpos != dial.run("reactions.dial").final_qpos
    again = dial.run("reactions.dial", disturb=[spec])
    assert again.final_qpos == result.final_qpos  # deterministic


def test_a_dropped_out_sensor_cannot_fire_its_monitor() -> None:
    # reactions.dial watches the index pad: with the index's tactile array out from the
    # start, the touch goes unnoticed, the fixed-length move drives on into the block, and
    # the light-touch criterion fails (docs/language.md, "Sensor dropouts").
    result = dial.run("reactions.dial", disturb=["sense sensor=tactile:index at=0"])
    assert result.summary.ok and not result.ok
    assert result.log.of("monitor") == [] and not result.success["light_touch"]
