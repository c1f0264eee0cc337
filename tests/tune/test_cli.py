"""``dial tune`` on the command line: usage errors, and one small sweep on the real engine."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from dial.cli import main
from dial.resources import resolve_script
from dial.tune import plan
from dial.tune.trial import engine_backend, run_trial

from ..conftest import NEEDS_PLOT


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["--ticks", "0.5:0.1:3"],
            "dial: --ticks: need 0 < A <= B <= 60 s (as @tick), got A=0.5 s and B=0.1 s",
        ),
        (["--ticks", "0.1:0.5"], "dial: --ticks: expected A:B:N (e.g. 0.05:0.5:10), got"),
        (["--ticks", "0.1:0.5:3", "--trials", "0"], "dial: --trials must be at least 1, got 0"),
        (["--ticks", "0.1:0.5:3", "--jobs", "0"], "dial: --jobs must be at least 1, got 0"),
        (["--ticks", "0.1:0.5:3", "--seed", "-1"], "dial: --seed must be 0 or more, got -1"),
        (["--ticks", "0.1:0.5:3", "--perturb", "-2"], "dial: --perturb must be 0 mm or more"),
        (
            ["--ticks", "0.1:0.5:3", "--disturb", "push body=x"],
            "dial: --disturb 'push body=x': missing at=",
        ),
        (["--ticks", "0.1:0.5:3", "--plot", "p.txt"], "dial: --plot writes a .png file, not"),
        (
            ["--ticks", "0.1:0.5:3", "--disturb", "push body=nosuch force=1,0,0 at=0 for=1"],
            "dial: --disturb 'push body=nosuch force=1,0,0 at=0 for=1': no body 'nosuch' in "
            "this scene; valid bodies: hand_base, ",
        ),
    ],
)
def test_usage_errors_exit_2_with_a_clear_message(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["tune", "lightbulb", *args]) == 2
    assert capsys.readouterr().err.startswith(message)


def test_without_ticks_the_sweep_runs_at_the_scripts_own_tick(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # reactions.dial says @tick 0.1 (the default without one would be 0.25 s).
    assert main(["tune", "reactions", "--jobs", "1", "--json"]) == 0
    table = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert [(t["tick"], t["trials"], t["successes"]) for t in table["ticks"]] == [(0.1, 1, 1)]


def test_a_script_error_stops_the_sweep_before_it_starts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.dial"
    bad.write_text("% go hand_pos x\n\ngo #\n")
    assert main(["tune", str(bad), "--ticks", "0.1:0.2:2"]) == 1
    assert "unknown instruction 'hand_pos'" in capsys.readouterr().err


def test_an_unwritable_plot_stops_the_sweep_before_it_starts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "no" / "p.png"
    assert main(["tune", "lightbulb", "--ticks", "0.1:0.2:2", "--plot", str(png)]) == 1
    captured = capsys.readouterr()
    assert captured.err == f"dial: cannot write the plot: no such directory '{png.parent}'\n"
    assert captured.out == ""  # no trial ran


@NEEDS_PLOT
def test_small_lightbulb_sweep_prints_table_json_and_plot(
    in_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "sweep.png"
    args = ["tune", "scripts/lightbulb.dial", "--ticks", "0.05:0.1:2", "--jobs", "2"]
    status = main([*args, "--json", "--plot", str(png)])
    out = capsys.readouterr().out
    table = json.loads(out.splitlines()[-1])
    assert status == (0 if table["fastest_reliable_tick"] is not None else 1)
    assert [(t["tick"], t["trials"]) for t in table["ticks"]] == [(0.05, 1), (0.1, 1)]
    assert all(t["tick_length"] == t["tick"] for t in table["ticks"])
    assert "tick (s)" in out and f"plot written to {png}" in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_scene_reaches_the_check_and_every_trial(
    in_root: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # explore.dial does not check in the pour scene: the sweep never starts.
    args = ["tune", "scripts/explore.dial", "--ticks", "0.1:0.2:2", "--scene", "pour"]
    assert main(args) == 1
    assert "unknown program 'to_probe' in scene 'pour'" in capsys.readouterr().err
    trials = plan("/x/go.dial", "go.dial", (0.1, 0.2), 2, scene="explore_block")
    assert {t.scene for t in trials} == {"explore_block"}
    # A worker loads the script in the trial's scene (here one that does not exist).
    bad = replace(trials[0], script=str(in_root / "scripts" / "explore.dial"), scene="kitchen")
    result = run_trial(engine_backend, bad)
    assert not result.ok and "unknown scene 'kitchen'" in (result.error or "")


def test_a_disturbance_reaches_every_trial_and_the_json(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # reactions.dial watches the index pad; with its tactile array out, the touch goes
    # unnoticed and the light-touch criterion fails (tests/engine/test_disturb.py).
    drop = "sense sensor=tactile:index at=0"
    trials = plan(str(resolve_script("reactions")), "reactions.dial", (0.1,), 2, disturb=(drop,))
    assert {t.disturb for t in trials} == {(drop,)}
    disturbed = [run_trial(engine_backend, t) for t in trials]
    assert [(r.ok, r.failed) for r in disturbed] == [(False, ("light_touch",))] * 2
    assert run_trial(engine_backend, replace(trials[0], disturb=())).ok
    args = ["tune", "reactions", "--ticks", "0.1:0.1:1", "--jobs", "1", "--json"]
    assert main([*args, "--disturb", drop]) == 1
    table = json.loads(capsys.readouterr().out.splitlines()[-1])
    assert table["disturb"] == [drop] and table["ticks"][0]["successes"] == 0
