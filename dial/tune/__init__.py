"""Tick-speed tuning: run a script over a grid of tick lengths and trials (``dial tune``).

The layers: :mod:`~dial.tune.grid` plans the trials, :mod:`~dial.tune.trial`
runs one on a backend (the engine, or a fake robot in tests),
:mod:`~dial.tune.executor` maps them over worker processes and
:mod:`~dial.tune.ray_executor` over Ray tasks (:mod:`~dial.tune.models` keeps a
worker's compiled models), and :mod:`~dial.tune.report` turns the results into
the table, the verdict and the JSON object.
"""

from dial.tune.command import TuneOptions, tune
from dial.tune.executor import WORKER_DIED, Executor, ItemsDone, ProcessExecutor, SerialExecutor
from dial.tune.grid import Trial, parse_ticks, plan, trial_seed
from dial.tune.ray_executor import RayExecutor
from dial.tune.report import TickRow, fastest_reliable, render_table, summarise, to_json, verdict
from dial.tune.trial import (
    Backend,
    TrialResult,
    TrialRun,
    engine_backend,
    failed_trial,
    run_trial,
    sweep,
)

__all__ = [
    "WORKER_DIED",
    "Backend",
    "Executor",
    "ItemsDone",
    "ProcessExecutor",
    "RayExecutor",
    "SerialExecutor",
    "TickRow",
    "Trial",
    "TrialResult",
    "TrialRun",
    "TuneOptions",
    "engine_backend",
    "failed_trial",
    "fastest_reliable",
    "parse_ticks",
    "plan",
    "render_table",
    "run_trial",
    "summarise",
    "sweep",
    "to_json",
    "trial_seed",
    "tune",
    "verdict",
]
