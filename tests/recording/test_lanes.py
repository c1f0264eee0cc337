"""Event lanes from log records: script order, outcomes, holds and markers (lanes.py)."""

from __future__ import annotations

import json
from typing import Any

import pytest

from dial.parser import load
from dial.recording.lanes import DEFAULT_TICK, LanePlan, Lanes, Phase
from dial.resources import resolve_script
from dial.scene import load_scene_names
from tests.conftest import ROOT


def _feed(lanes: Lanes, records: list[dict[str, Any]]) -> list[Phase]:
    phases = [p for r in records for p in lanes.feed(r)]
    return phases + lanes.flush()


def _tick(k: int, t0: float, t1: float, block_tick: int, stretch: int = 0) -> dict[str, Any]:
    return {"kind": "tick", "tick": k, "block_tick": block_tick, "t0": t0, "t1": t1,
            "stretch": stretch}  # fmt: skip


def test_the_plan_orders_lanes_as_the_script_and_groups_a_callee() -> None:
    script = load(resolve_script("explore.dial"), loader=load_scene_names)
    plan = LanePlan.from_script(script)
    assert plan.order[:9] == (
        ("reach",), ("point",), ("find",), ("again",), ("give_up",), ("lift",), ("aside",),
        ("wide",), ("clear",),
    )  # fmt: skip
    callees = [k for k in plan.order if len(k) == 2]
    # containment calls two scripts of its own: a lane group each, in the order first met.
    assert list(dict.fromkeys(k[0] for k in callees)) == [
        "explore_surface", "containment", "containment_top", "containment_side"
    ]  # fmt: skip
    assert (
        plan.holds[("", 32, 1)] == 2 and plan.holds[("", 33, 1)] == 4
    )  # reach #===--, point #----
    lanes = Lanes(plan)
    assert lanes.path(("reach",)) == ("01_reach",)
    assert lanes.path(("explore_surface", "reach")) == ("10_explore_surface", "01_reach")
    assert lanes.path(("containment", "reach_top")) == ("11_containment", "01_reach_top")
    assert LanePlan.from_record(json.loads(json.dumps(plan.as_record()))) == plan


def test_runs_carry_their_outcome_and_holds_follow() -> None:
    # `#--` on line 7 from block tick 1: a one-tick run held for two ticks.
    lanes = Lanes(LanePlan((("open",), ("grab",)), holds={("", 7, 1): 2}))
    phases = _feed(
        lanes,
        [
            {"kind": "start", "event": "open", "line": 7, "tick": 1, "t": 0.0},
            {"kind": "end", "event": "open", "line": 7, "tick": 1, "t": 0.0, "outcome": "done"},
            _tick(1, 0.0, 0.1, 1),
            {"kind": "start", "event": "grab", "line": 8, "tick": 2, "t": 0.1},
            {"kind": "end", "event": "grab", "line": 8, "tick": 2, "t": 0.5, "outcome": "missed"},
            _tick(2, 0.1, 0.5, 2, stretch=40),
            _tick(3, 0.5, 0.6, 3),
        ],
    )
    assert phases == [
        Phase(("01_open",), "running", 0.0, 1),
        Phase(("01_open",), "done", 0.0, 1),  # over the running, from its start
        Phase(("01_open",), "held", 0.1, 2),  # took no time: drawn over its tick
        Phase(("02_grab",), "running", 0.1, 2),
        Phase(("02_grab",), "missed", 0.1, 2),
        Phase(("02_grab",), None, 0.5, 3),
        Phase(("01_open",), None, 0.6, 4),  # held through ticks 2 and 3
    ]


def test_conditions_are_markers_on_their_event_or_below_its_runs() -> None:
    plan = LanePlan((("grab",), ("ringing",)), condition_only=frozenset({("ringing",)}))
    lanes = Lanes(plan)
    records = [
        {"kind": "start", "event": "grab", "line": 9, "tick": 1, "t": 0.0},
        {"kind": "end", "event": "grab", "line": 9, "tick": 1, "t": 0.1, "outcome": "done"},
        _tick(1, 0.0, 0.1, 1),
        {"kind": "end", "event": "ringing", "line": 4, "tick": 1, "t": 0.1, "outcome": "missed"},
        {"kind": "condition", "condition": "!ringing", "value": True, "tick": 1, "t": 0.1},
        {"kind": "condition", "condition": "grab", "value": True, "tick": 1, "t": 0.1},
    ]
    phases = _feed(lanes, records)
    assert Phase(("02_ringing",), "false", 0.1, 1) in phases  # !ringing true: ringing false
    assert Phase(("01_grab.tests",), "true", 0.1, 1) in phases  # beside grab's runs
    assert Phase(("02_ringing",), None, pytest.approx(0.2), 2) in phases  # one tick wide
    assert not [p for p in phases if p.lane == ("02_ringing",) and p.state == "running"]


def test_monitors_preemptions_and_disturbances_are_drawn() -> None:
    """The records of reactions (DESIGN 2.7, 2.8), as the engine will write them."""
    lanes = Lanes(LanePlan((("touch",), ("move",)), holds={("", 5, 1): 3}))
    records = [
        {"kind": "start", "event": "touch", "line": 4, "tick": 1, "t": 0.0},
        {"kind": "start", "event": "move", "line": 5, "tick": 1, "t": 0.0},
        {"kind": "disturb", "what": "push cup", "phase": "begin", "t": 0.05, "tick": 1},
        {"kind": "monitor", "event": "touch", "condition": "touch", "tick": 1, "t": 0.07,
         "period": 7, "step": 35},
        {"kind": "end", "event": "move", "line": 5, "tick": 1, "t": 0.07, "outcome": "preempted"},
        {"kind": "end", "event": "touch", "line": 4, "tick": 1, "t": 0.07, "outcome": "done"},
        _tick(1, 0.0, 0.07, 1),
        {"kind": "disturb", "what": "push cup", "phase": "end", "t": 0.3, "tick": 4},
    ]  # fmt: skip
    phases = _feed(lanes, records)
    assert Phase(("disturb", "push_cup"), "disturbed", 0.05, 1) in phases
    assert Phase(("disturb", "push_cup"), None, 0.3, 5) in phases
    assert Phase(("01_touch.tests",), "fired", 0.07, 1) in phases
    assert Phase(("02_move",), "preempted", 0.0, 1) in phases
    assert not [p for p in phases if p.state == "held"]  # a preempted run holds nothing
    assert [p for p in phases if p.lane == ("02_move",)][-1] == Phase(("02_move",), None, 0.07, 2)


def test_without_a_plan_lanes_come_in_the_order_events_first_run() -> None:
    lanes = Lanes()
    records = [
        {"kind": "start", "event": "zeta", "line": 9, "tick": 1, "t": 0.0},
        {"kind": "start", "event": "touch", "line": 2, "tick": 1, "t": 0.0, "script": "a/sub.dial"},
        {"kind": "start", "event": "alpha", "line": 3, "tick": 1, "t": 0.0},
    ]
    _feed(lanes, records)
    assert lanes.path(("zeta",)) == ("01_zeta",)
    assert lanes.path(("sub", "touch")) == ("02_sub", "01_touch")
    assert lanes.path(("alpha",)) == ("03_alpha",)
    assert lanes.width == DEFAULT_TICK  # no tick has ended yet


def test_the_plan_has_lanes_for_watched_events_and_reactions() -> None:
    """``~`` lines and ``@on`` bodies (DESIGN 2.7): each watched or reacting event a lane."""
    script = load(ROOT / "tests" / "data" / "valid" / "reactions_nested.dial")
    plan = LanePlan.from_script(script)
    assert plan.order == (
        ("reach",), ("touch",), ("pos",), ("back",), ("slow",), ("press",), ("snap",),
        ("sub", "open"),
    )  # fmt: skip
