"""Runs and sweeps into datasets: what the frames hold, against the physics and the log; the
run unchanged; sweeps byte-identical on any executor; bad input as one line."""

from __future__ import annotations

import json
import signal
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pyarrow", reason="the dataset tests need the 'dataset' extra (pyarrow)")

import pyarrow.parquet as pq

import dial
from dial.cli import main
from dial.dataset.plan import Request
from dial.dataset.writer import DatasetWriter
from dial.tune import ProcessExecutor, SerialExecutor, trial_seed

from ..conftest import json_records
from . import layout
from .helpers import Exact, digest, sweep

SCRIPT = "reactions.dial"


def _frames(root: Path) -> dict[str, np.ndarray]:
    table = pq.read_table(root / "data/chunk-000/file-000.parquet")
    return {name: np.array(table.column(name).to_pylist()) for name in table.column_names}


@pytest.mark.parametrize("fps", [50, 30])
def test_frames_are_the_physics_at_the_fps_grid_and_the_log_is_unchanged(
    tmp_path: Path, fps: int
) -> None:
    exact = Exact()
    plain = dial.run(SCRIPT, perturb=5, seed=2, log_states=True)
    result = dial.run(
        SCRIPT, perturb=5, seed=2, log_states=True, observers=[exact], dataset=tmp_path, fps=fps
    )
    assert json_records(result) == json_records(plain)  # the dataset changes nothing
    assert result.final_qpos == plain.final_qpos
    frames = _frames(tmp_path)
    n = len(frames["frame_index"])
    due = [(2 * k * 100 + fps) // (2 * fps) for k in range(n)]  # control period of frame k
    periods = len(exact.states) - 1
    assert due[-1] <= periods < (2 * n * 100 + fps) // (2 * fps)  # every frame the run had
    state, action = frames["observation.state"], frames["action"]
    want_state = np.array([exact.states[p] for p in due])
    want_action = np.array([exact.controls[p + 1] for p in due])  # the next period's command
    eps = np.finfo(np.float32).eps
    np.testing.assert_allclose(state, want_state, rtol=eps, atol=eps)
    np.testing.assert_allclose(action, want_action, rtol=eps, atol=eps)
    states = {round(r["t"], 6): r["qpos"] for r in result.log.of("state")}  # 25 Hz, 4 digits
    matched = 0
    for k in range(n):
        t = round(due[k] / 100, 6)
        if t in states:
            np.testing.assert_allclose(
                state[k], np.array(states[t])[exact.qpos], atol=0.5e-4 + 1e-6
            )
            matched += 1
    assert matched >= 5  # at 50 fps every other frame; at 30 fps where the grids meet
    read = layout.check(tmp_path)
    assert read["info"]["fps"] == fps
    episode = read["episodes"][0]
    assert episode["dial/script"] == SCRIPT and episode["dial/scene"] == "reactions"
    assert episode["dial/seed"] == 2 and episode["dial/perturb_mm"] == pytest.approx(5.0)
    assert episode["dial/success"] is result.ok
    assert json.loads(episode["dial/outcomes"]) == result.summary.outcomes
    assert frames["next.success"][-1] == result.ok and not frames["next.success"][:-1].any()


def test_a_custom_sweep_appends_episodes_through_one_writer(tmp_path: Path) -> None:
    with DatasetWriter(tmp_path) as writer:
        for seed in range(2):
            dial.run(SCRIPT, perturb=5, seed=seed, dataset=writer)
        assert writer.added == 2
    assert layout.check(tmp_path)["info"]["total_episodes"] == 2


def test_a_resumed_runs_episode_starts_where_it_resumes(tmp_path: Path) -> None:
    dial.run(SCRIPT, save_at=(2, tmp_path / "s.state"))
    result = dial.run(SCRIPT, resume=tmp_path / "s.state", dataset=tmp_path / "d")
    resumed = result.log.of("resume")[0]
    periods = round((result.summary.sim_time - float(resumed["t"])) * 100)  # type: ignore[arg-type]
    frames = _frames(tmp_path / "d")["frame_index"]
    assert len(frames) == periods // 2 + 1  # 50 fps: every other period, and the first
    layout.check(tmp_path / "d")


def test_an_interrupted_run_writes_no_episode(tmp_path: Path) -> None:
    def stop(tick: int, t: float, running: list[str]) -> None:
        if tick == 3:
            signal.raise_signal(signal.SIGINT)

    result = dial.run(SCRIPT, progress=stop, dataset=tmp_path / "d")
    assert result.summary.interrupted == "SIGINT"
    assert not (tmp_path / "d").exists()


def _cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    status = main(list(argv))
    return status, capsys.readouterr().err


def test_bad_dataset_input_is_one_line_and_changes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    run = ["run", SCRIPT, "--quiet"]
    assert _cli(capsys, *run, "--dataset", str(tmp_path / "d"))[0] == 0
    before = digest(tmp_path / "d")
    d, f = str(tmp_path / "d"), str(tmp_path / "f")
    (tmp_path / "f").write_text("")
    other = "names[0] is surface_block_x in the dataset, lightbulb_bulb_x in this run"
    cases = [
        ([*run, "--dataset", d, "--fps", "0"], 2, "--fps must be a whole number"),
        ([*run, "--fps", "20"], 2, "--fps goes with --dataset DIR"),
        (["run", "lightbulb.dial", "--dataset", d], 1, other),
        ([*run, "--dataset", d, "--fps", "25"], 1, "it is at 50 fps, not 25"),
        ([*run, "--dataset", f], 1, f"'{f}' is a file"),
        ([*run, "--dataset", d, "--cameras", "nope"], 2, "has no camera 'nope' (it has: task)"),
        ([*run, "--dataset", d, "--cameras", ","], 2, "--cameras: expected camera names"),
    ]
    for argv, status, message in cases:
        got, err = _cli(capsys, *argv)
        assert (got, err.count("\n")) == (status, 1), (argv, err)
        assert message in err, (argv, err)
    assert digest(tmp_path / "d") == before


def test_without_pyarrow_the_error_names_the_extra(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda n, *a: None if n == "pyarrow" else real(n, *a)
    )
    status, err = _cli(capsys, "tune", SCRIPT, "--ticks", "0.1:0.1:1", "--dataset", str(tmp_path))
    assert (status, err) == (2, "dial: --dataset needs pyarrow: pip install 'dial[dataset]'\n")


def test_a_sweep_gives_the_same_files_on_one_or_two_workers(tmp_path: Path) -> None:
    out1 = sweep(tmp_path / "j1", ProcessExecutor(1))
    out2 = sweep(tmp_path / "j2", ProcessExecutor(2))
    assert out1 == out2
    assert digest(tmp_path / "j1") == digest(tmp_path / "j2")
    read = layout.check(tmp_path / "j1")
    assert [e["dial/seed"] for e in read["episodes"]] == [trial_seed(0, k) for k in range(3)]


def test_successful_only_leaves_the_failed_trials_out(tmp_path: Path) -> None:
    # reactions.dial fails at 0.03 s (docs/tuning.md) and succeeds at 0.1 s.
    request = Request(successful_only=True)
    sweep(tmp_path, SerialExecutor(), ticks="0.03:0.1:2", trials=1, request=request)
    read = layout.check(tmp_path)
    assert [(e["dial/tick"], e["dial/success"]) for e in read["episodes"]] == [(0.1, True)]
