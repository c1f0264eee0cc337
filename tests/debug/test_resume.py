"""Save at a block boundary and resume exactly (DESIGN 6.1): the continuation's records and
final state are the uninterrupted run's, byte for byte apart from wall time."""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

import dial
from dial.cli import main

from ..conftest import ROOT, json_records


def _check_exact(script: str, scene: str | None, block: int, tmp_path: Path) -> None:
    state = tmp_path / f"{Path(script).stem}-{block}.state"
    full = dial.run(dial.load(script, scene=scene), save_at=(block, state))
    assert full.saved == ((block, state),), "the save point was never reached"
    resumed = dial.run(dial.load(script, scene=scene), resume=state)
    tail = [r for r in json_records(resumed) if r["kind"] not in ("scene", "resume")]
    assert tail == json_records(full)[-len(tail) :]
    assert resumed.final_qpos == full.final_qpos  # bit for bit
    assert resumed.ok == full.ok and resumed.summary.sim_time == full.summary.sim_time
    assert len(tail) < len(json_records(full)) - 2  # it did not simply run everything again


@pytest.mark.parametrize(
    ("script", "scene", "block"),
    [
        ("lightbulb.dial", None, 7),  # inside '@repeat until !tug' (its second iteration)
        ("lightbulb.dial", None, 12),  # the block after that loop
        ("explore_surface.dial", None, 20),  # inside '@repeat until' loops and '@if'
        ("explore.dial", "explore_block", 2),  # the @call of a procedure comes after it
        ("explore.dial", "explore_block", 4),  # inside the called procedure
        ("reactions.dial", None, 3),  # inside a reaction
    ],
)
def test_resume_is_exact(script: str, scene: str | None, block: int, tmp_path: Path) -> None:
    _check_exact(script, scene, block, tmp_path)


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A copy of lightbulb.dial (and its world) and a state saved before its block 12."""
    folder = tmp_path_factory.mktemp("edits")
    script = folder / "lightbulb.dial"
    shutil.copy(ROOT / "scripts" / "lightbulb.dial", script)
    state = folder / "lb.state"
    assert main(["run", str(script), "--save-at", "block:12", str(state), "--quiet"]) == 0
    return script, state


def test_resuming_an_edited_later_block_runs_the_edit(
    saved: tuple[Path, Path], tmp_path: Path
) -> None:
    script, state = saved
    edited = tmp_path / "lightbulb.dial"
    text = script.read_text()
    # The last block (line 150 on): retract 10 ticks -> a shorter, 6-tick retract.
    assert "retract_arm  #=========\n" in text
    edited.write_text(text.replace("retract_arm  #=========\n", "retract_arm  #=====\n"))
    before = dial.run(dial.load(script), resume=state)
    after = dial.run(dial.load(edited), resume=state)
    assert after.summary.ticks == before.summary.ticks - 4
    ends = [r for r in after.log.of("end") if r["event"] == "retract_arm"]
    assert ends and ends[-1]["outcome"] == "done"


def test_a_resumed_summary_times_the_resumed_part(
    saved: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    script, state = saved
    main(["run", str(script), "--resume", str(state)])
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("simulated "))
    total, rest = line.removeprefix("simulated ").split(" s (", 1)
    part, rest = rest.split(" s after resuming at ", 1)
    since, rest = rest.split(" s) in ", 1)
    assert rest.split(" s wall (real-time factor ", 1)[1]  # counted over the part
    assert float(part) == pytest.approx(float(total) - float(since), abs=0.011)
    assert float(since) > 30  # lightbulb's block 12 starts at 30.56 s


def test_an_edited_earlier_line_is_named(
    saved: tuple[Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    script, state = saved
    edited = tmp_path / "lightbulb.dial"
    lines = script.read_text().split("\n")
    lines[57] = lines[57] + "  // a comment is a change too"  # line 58
    edited.write_text("\n".join(lines))
    assert main(["run", str(edited), "--resume", str(state), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"dial: {edited}:58:1: this line changed since the state was saved")
    assert err.count("\n") == 1 and "Traceback" not in err


def _set(field: str, key: str | int | None, value: object) -> Callable[[str], str]:
    """A damage: the state file's text with ``data[field][key]`` (or ``data[field]``) set."""

    def damage(text: str) -> str:
        data = json.loads(text)
        if key is None:
            data[field] = value
        else:
            data[field][key] = value
        return json.dumps(data)

    return damage


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (lambda s: s[: len(s) // 2], "is corrupt or truncated (not JSON)"),
        (lambda s: s.replace('"version": 1', '"version": 99'), "has format version 99"),
        (lambda s: s.replace('"counts"', '"countz"'), "is corrupt or truncated ('counts')"),
        (lambda s: "\x00\x01binary", "is corrupt or truncated (not JSON)"),
        (lambda s: "[1, 2]", "is not a dial state file"),
        # Valid JSON with a field of the wrong type or size (was a traceback, or a broadcast).
        (_set("block", None, "12"), "is corrupt or truncated (block '12')"),
        (_set("robot", "limp", [True]), "is corrupt (limp has not 16 flags)"),
        (_set("latest", 0, ["lightbulb.dial", "lower", "bogus"]), "is not a valid Outcome"),
        (_set("clock", None, [1, 2, 3]), "is corrupt ("),
    ],
)
def test_a_bad_state_file_is_one_line_and_exit_1(
    saved: tuple[Path, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    damage: object,
    message: str,
) -> None:
    script, state = saved
    bad = tmp_path / "bad.state"
    bad.write_text(damage(state.read_text()))  # type: ignore[operator]
    assert main(["run", str(script), "--resume", str(bad), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


def test_a_state_file_of_another_script(
    saved: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    _, state = saved
    assert main(["run", "pour.dial", "--resume", str(state), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err == (
        f"dial: state file '{state}' was saved from script 'lightbulb.dial', not 'pour.dial'\n"
    )


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--save-at", "block:0", "x.state"], "--save-at: expected block:N FILE"),
        (["--save-at", "tick:3", "x.state"], "--save-at: expected block:N FILE"),
        (["--resume", "x.state", "--tick", "0.1"], "--resume takes the tick, seed"),
        (["--break", "nosuch"], "--break nosuch: no event 'nosuch' in the script"),
        (["--break", "tick:0"], "--break tick:0: expected tick:N"),
    ],
)
def test_debugging_usage_errors(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["run", "lightbulb.dial", *argv, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"dial: {message}") and err.count("\n") == 1


def test_a_save_point_never_reached_is_an_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    state = tmp_path / "x.state"
    assert main(["run", "reactions.dial", "--save-at", "block:9", str(state), "--quiet"]) == 1
    assert "nothing was saved" in capsys.readouterr().err and not state.exists()


TOP = """\
@scene surface
@tick 0.1
% to     puma_command "ex to_block"
% back   arm_move     0 0 0.01 frame=world

to     #==
@call sub.dial
@if to
back   #=
@end
"""
SUB = """\
@scene surface
@tick 0.1
% open   hand_pose    "open_hand"
% down   arm_move     0 0 -0.01 frame=world

open   #

down   #=
@if open
down   #=
@end
"""


def test_resume_from_another_directory(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Saved inside a called script run as ``dial run top.dial`` from its folder, resumed by
    another path from elsewhere: the callee is checked where the script calls it now, and the
    outcomes of both scripts before the save (which conditions read) carry over."""
    folder, elsewhere = tmp_path / "scripts", tmp_path / "elsewhere"
    folder.mkdir()
    elsewhere.mkdir()
    (folder / "top.dial").write_text(TOP)
    (folder / "sub.dial").write_text(SUB)
    state = folder / "sub.state"
    monkeypatch.chdir(folder)
    full = dial.run(dial.load("top.dial"), save_at=(3, state))  # block 3: sub's first down
    assert full.saved == ((3, state),)
    monkeypatch.chdir(elsewhere)
    resumed = dial.run(dial.load(folder / "top.dial"), resume=state)

    def named(records: list[dict[str, object]]) -> list[dict[str, object]]:
        # A called script's records name it by its path as run: the same file here.
        return [
            {**r, **({"script": Path(str(r["script"])).name} if "script" in r else {})}
            for r in records
        ]

    tail = named([r for r in json_records(resumed) if r["kind"] not in ("scene", "resume")])
    assert len(tail) > 4 and tail == named(json_records(full))[-len(tail) :]
    assert [r["value"] for r in resumed.log.of("condition")] == [True, True]
    assert resumed.final_qpos == full.final_qpos
