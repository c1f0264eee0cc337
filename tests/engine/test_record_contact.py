"""record_contact at=stop and source=links: where the thumb touched the containment box.

The thumb pad (pose probe, hand pointing down) comes in on the box's -x face square on, and then
at azimuth 225 deg, where the box's vertical edge meets the side of the pad, outside the
taxels. The box stands at (0.52, 0, 0.505) with half-sizes 30 x 25 x 35 mm
(objects_containment.xml): its -x face is the plane x = 0.49, its edge the line x = 0.49,
y = -0.025.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import dial
from dial.engine import RunResult

FACE_X, EDGE_Y = 0.49, -0.025  # m
TOL = 0.001  # m: a contact point lies within half the penetration of the surface

WORLD = """\
extends = "containment"
[locations]
# 10 cm above side_180
over_180 = { object = "target", pos = [-0.0257, 0, 0.2125], rpy = [167, 0, 90], axes = "world" }
[programs]
to_face = \"\"\"
MOVE over_180
MOVES side_180
\"\"\"
to_edge = \"\"\"
MOVES side_202_5
MOVES side_225
\"\"\"
"""

IN = "0 0.974 0.225 frame=tool speed=80mm/s sense=thumb press=0.5mm"
SCRIPT = f"""\
@scene world.toml
@tick 0.1
% to_face   puma_command   "ex to_face"
% to_edge   puma_command   "ex to_edge"
% probe     hand_pose      "probe"
% before    record_contact finger=thumb into=pad at=stop
% in        guarded_move   {IN} max=45mm until=tactile:0.02mm,force:3N
% pad       record_contact finger=thumb into=pad at=stop
% link      record_contact finger=thumb into=link at=stop source=links
% back      arm_move       0 -9.74mm -2.25mm
% out       guarded_move   0 -0.974 -0.225 frame=tool max=5mm until=tactile:0.02mm sense=thumb
% after     record_contact finger=thumb into=pad at=stop
% free      record_contact finger=thumb into=link source=links
% edge_pad  record_contact finger=thumb into=pad at=stop
% edge_link record_contact finger=thumb into=link at=stop source=links

to_face   #=====--
probe     #
before     #

in        #

pad       #
link      #
back      #
out        #
after       #
free        #

to_edge   #==-
in            #

edge_pad  #
edge_link #
"""


@pytest.fixture(scope="module")
def script(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = Path(tmp_path_factory.mktemp("record"))
    (folder / "world.toml").write_text(WORLD)
    (folder / "record.dial").write_text(SCRIPT)
    return folder / "record.dial"


@pytest.fixture(scope="module")
def run(script: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[RunResult, Path]:
    """The run, saving its state before block 5 (the first 'edge_pad'): between the guarded
    move that stopped on the edge and the records of that stop."""
    state = Path(tmp_path_factory.mktemp("state")) / "record.state"
    result = dial.run(dial.load(script), save_at=(5, state))
    assert result.summary.error is None, result.summary.error
    assert result.saved == ((5, state),)
    return result, state


@pytest.fixture(scope="module")
def ends(run: tuple[RunResult, Path]) -> dict[str, list[dict[str, Any]]]:
    out: dict[str, list[dict[str, Any]]] = {}
    for record in run[0].log.of("end"):
        out.setdefault(record["event"], []).append(record)
    return out


def _point(record: dict[str, Any]) -> np.ndarray:
    assert record["outcome"] == "done", record
    return np.asarray(record["data"]["point"])


def test_a_square_touch_is_located_on_the_face_by_taxels_and_by_links(
    ends: dict[str, list[dict[str, Any]]],
) -> None:
    first = ends["in"][0]
    assert first["outcome"] == "done" and first["data"]["kind"] == "tactile"
    pad, link = _point(ends["pad"][0]), _point(ends["link"][0])
    assert pad[0] == pytest.approx(FACE_X, abs=TOL)
    assert link[0] == pytest.approx(FACE_X, abs=TOL)
    # Both on the part of the face the pad covers: 15 mm tall, 20 mm wide.
    assert np.linalg.norm(pad[1:] - link[1:]) < 0.012


def test_at_stop_needs_a_stop_of_the_latest_guarded_move(
    ends: dict[str, list[dict[str, Any]]],
) -> None:
    # Before any guarded move, and after one that ended without a contact.
    for name in ("before", "after"):
        (record,) = ends[name]
        assert record["outcome"] == "missed"
        assert record["message"] == "no guarded move stopped on a contact of the thumb"
    assert ends["out"][0]["outcome"] == "missed"
    # Now, clear of the box, the links touch nothing.
    (free,) = ends["free"]
    assert free["outcome"] == "missed" and "links touched nothing now" in free["message"]


def test_an_edge_outside_the_taxels_is_located_on_the_links(
    ends: dict[str, list[dict[str, Any]]],
) -> None:
    second = ends["in"][1]
    assert second["outcome"] == "done" and second["data"]["kind"] == "force"
    (pad,) = ends["edge_pad"]
    assert pad["outcome"] == "missed" and "array touched nothing at the stop" in pad["message"]
    edge = _point(ends["edge_link"][0])
    assert edge[0] == pytest.approx(FACE_X, abs=TOL)
    assert edge[1] == pytest.approx(EDGE_Y, abs=TOL)


def test_a_resumed_run_records_the_stop_it_saved(script: Path, run: tuple[RunResult, Path]) -> None:
    """The stop contacts are part of a run's state: resumed between the stop and its records,
    the run records the same points, bit for bit."""
    full, state = run
    resumed = dial.run(dial.load(script), resume=state)
    points = [r["data"]["point"] for r in resumed.log.of("end") if r["event"] == "edge_link"]
    assert points == [r["data"]["point"] for r in full.log.of("end") if r["event"] == "edge_link"]
    assert resumed.final_qpos == full.final_qpos
