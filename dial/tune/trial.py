"""Running one trial, on any backend, and the sweep over all of them.

A backend turns a :class:`Trial` into a :class:`RunReport`. The real one runs
the MuJoCo engine; tests pass a fake robot with a physical limit
(:mod:`dial.testing.limited`). Whatever the backend does, :func:`run_trial`
turns it into a :class:`TrialResult`: an exception is a failed trial with its
reason, never a failed sweep.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from dial.errors import DialError
from dial.tune.executor import Executor, ItemsDone
from dial.tune.grid import Trial


@dataclass(frozen=True)
class RunReport:
    """What a backend reports of one run."""

    success: Mapping[str, bool]  # criterion name -> held
    sim_time: float  # simulated s from the first tick to the end (or the abort)
    tick_length: float  # s, the tick as run: a whole number of control periods
    error: str | None = None  # why the run aborted (timeout, error, safety monitor)


@dataclass(frozen=True)
class TrialResult:
    """One trial's result. ``sim_time`` and ``tick_length`` are None when it raised."""

    tick: float
    trial: int
    seed: int
    ok: bool
    sim_time: float | None
    tick_length: float | None
    failed: tuple[str, ...]  # criteria that did not hold
    error: str | None


Backend = Callable[[Trial], RunReport]


def engine_backend(trial: Trial) -> RunReport:
    """Run the trial on the MuJoCo engine, as ``dial run --tick --seed --perturb --scene
    --disturb`` would."""
    from dial.disturb import parse_disturbance
    from dial.engine import RunOptions, run  # in the worker: the parent needs no MuJoCo
    from dial.parser.check import load
    from dial.scene import load_scene_names

    script = load(trial.script, loader=load_scene_names, display=trial.display, scene=trial.scene)
    disturb = tuple(parse_disturbance(d) for d in trial.disturb)  # texts cross the wire
    options = RunOptions(trial.tick, seed=trial.seed, perturb_mm=trial.perturb_mm, disturb=disturb)
    result = run(script, options)
    summary = result.summary
    error = str(summary.error) if summary.error is not None else None
    return RunReport(result.success, summary.sim_time, summary.tick_length, error)


def run_trial(backend: Backend, trial: Trial) -> TrialResult:
    """Run one trial; any exception (a bug, a failed IK, a diverged state) fails only it."""
    try:
        report = backend(trial)
    except DialError as e:
        return failed_trial(trial, str(e))
    except Exception as e:  # an unexpected error fails this trial, not the sweep
        return failed_trial(trial, f"{type(e).__name__}: {e}")
    failed = tuple(name for name, held in report.success.items() if not held)
    return TrialResult(
        trial.tick,
        trial.trial,
        trial.seed,
        report.error is None and not failed,
        report.sim_time,
        report.tick_length,
        failed,
        report.error,
    )


def failed_trial(trial: Trial, reason: str) -> TrialResult:
    """A trial that produced no run report: it raised, or its worker process died."""
    return TrialResult(trial.tick, trial.trial, trial.seed, False, None, None, (), reason)


def sweep(
    trials: Sequence[Trial],
    executor: Executor,
    backend: Backend = engine_backend,
    progress: ItemsDone | None = None,
) -> list[TrialResult]:
    """Run every trial; results come back in the order of ``trials``, whatever ran first."""
    # Longest ticks first, so that the last trials to finish are short ones and the
    # workers end together (the results are put back in plan order below).
    order = sorted(range(len(trials)), key=lambda i: (-trials[i].tick, i))
    ran = executor.map(
        functools.partial(run_trial, backend), [trials[i] for i in order], failed_trial, progress
    )
    by_index = dict(zip(order, ran, strict=True))
    return [by_index[i] for i in range(len(trials))]
