"""Sweeps as Ray tasks: the same output as the process pool, and a lost worker re-run.

One local Ray (2 CPUs, no dashboard) serves every test of this module. Its workers
get the test backends by value, as they cannot import the ``tests`` package.
"""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from io import StringIO
from pathlib import Path

import pytest

pytest.importorskip("ray", reason="the 'ray' extra is not installed: pip install -e '.[ray]'")
import ray
import ray.cloudpickle

from dial.cli import main
from dial.testing.limited import limited_backend
from dial.tune import (
    Backend,
    Executor,
    ProcessExecutor,
    SerialExecutor,
    TuneOptions,
    failed_trial,
    parse_ticks,
    plan,
    sweep,
    tune,
)
from dial.tune.executor import WORKER_DIED
from dial.tune.ray_executor import RayExecutor

from . import helpers


@pytest.fixture(scope="module")
def local_ray() -> Iterator[RayExecutor]:
    executor = RayExecutor(cpus=2)
    executor.connect()
    ray.cloudpickle.register_pickle_by_value(helpers)
    try:
        yield executor
    finally:
        ray.cloudpickle.unregister_pickle_by_value(helpers)
        executor.close()
    assert not ray.is_initialized()


def _tune(tmp_path: Path, executor: Executor, backend: Backend) -> tuple[int, str]:
    out, err = StringIO(), StringIO()
    script = str(helpers.write_go(tmp_path))
    options = TuneOptions(script, parse_ticks("0.05:0.5:10"), trials=2, json=True)
    status = tune(options, executor, backend, out, err)
    return status, out.getvalue()


def test_ray_prints_the_process_pools_table_and_json_byte_for_byte(
    tmp_path: Path, local_ray: RayExecutor
) -> None:
    status, out = _tune(tmp_path, local_ray, limited_backend)
    assert (status, out) == _tune(tmp_path, ProcessExecutor(2), limited_backend)
    assert local_ray.where == "on a local Ray with 2 CPUs"
    table = json.loads(out.splitlines()[-1])
    assert table["fastest_reliable_tick"] == 0.25
    assert [t["successes"] for t in table["ticks"]] == [0] * 4 + [2] * 6


def test_a_trial_that_always_kills_its_worker_is_lost_as_on_the_process_pool(
    tmp_path: Path, local_ray: RayExecutor
) -> None:
    trials = plan(str(helpers.write_go(tmp_path)), "go.dial", parse_ticks("0.2:0.35:4"), 1)
    expected = sweep(trials, SerialExecutor(), limited_backend)
    expected[2] = failed_trial(trials[2], WORKER_DIED)  # 0.3 s, helpers.BAD_TICK
    assert sweep(trials, local_ray, helpers.dying) == expected  # as in test_sweep.py


def test_a_worker_killed_in_the_middle_of_a_sweep_reruns_its_trial(
    tmp_path: Path, local_ray: RayExecutor
) -> None:
    trials = plan(str(helpers.write_go(tmp_path)), "go.dial", parse_ticks("0.05:0.5:10"), 1)
    done: list[int] = []
    results = sweep(trials, local_ray, helpers.dies_once, done.append)
    assert (tmp_path / "go.died-0").exists()  # the worker running 0.3 s did die
    assert results == sweep(trials, SerialExecutor(), limited_backend)
    assert done == list(range(1, 11))


def test_ctrl_c_cancels_the_tasks_not_yet_run(tmp_path: Path, local_ray: RayExecutor) -> None:
    # Ctrl-C arrives as the first result comes in (dial's CLI then exits 130): the tasks
    # still queued must never start. Each trial marks its start and then takes a second.
    trials = plan(str(helpers.write_go(tmp_path)), "go.dial", parse_ticks("0.1:1:10"), 1)

    def interrupt(done: int) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sweep(trials, local_ray, helpers.slow, interrupt)
    time.sleep(3.0)  # without the cancel, 2 CPUs would have started 4-6 more trials by now
    started = list(tmp_path.glob("go.started-*"))
    assert 1 <= len(started) <= 4, started  # the first pair, and a pair already handed out


def test_the_cli_runs_a_real_engine_trial_on_ray_as_in_processes(
    local_ray: RayExecutor, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["tune", "lightbulb", "--ticks", "0.05:0.05:1", "--json"]
    assert main([*args, "--executor", "ray"]) == 0
    on_ray = capsys.readouterr()
    assert "dial: 1 trials in " in on_ray.err and "s wall on this process's Ray" in on_ray.err
    assert main([*args, "--jobs", "1"]) == 0
    assert on_ray.out == capsys.readouterr().out
    table = json.loads(on_ray.out.splitlines()[-1])
    assert table["ticks"][0]["successes"] == 1
