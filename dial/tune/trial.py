"""Running one trial, on any backend, and the sweep over all of them.

A backend turns a :class:`Trial` into a :class:`TrialRun`. The real one runs
the MuJoCo engine; tests pass a fake robot with a physical limit
(:mod:`dial.testing.limited`). Whatever the backend does, :func:`run_trial`
turns it into a :class:`TrialResult`: an exception is a failed trial with its
reason, never a failed sweep.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from dial.errors import DialError
from dial.tune.executor import Each, Executor, ItemsDone
from dial.tune.grid import Trial

if TYPE_CHECKING:
    from dial.dataset.episode import Episode


@dataclass(frozen=True)
class TrialRun:
    """What a backend reports of one run."""

    success: Mapping[str, bool]  # criterion name -> held
    sim_time: float  # simulated s from the first tick to the end (or the abort)
    tick_length: float  # s, the tick as run: a whole number of control periods
    error: str | None = None  # why the run aborted (timeout, error, safety monitor)
    episode: Episode | None = None  # the run as a dataset's episode, if the trial asks


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
    episode: Episode | None = None  # until the parent has written it (dial.tune.episodes)


Backend = Callable[[Trial], TrialRun]


def engine_backend(trial: Trial) -> TrialRun:
    """Run the trial on the MuJoCo engine, as ``dial run --tick --seed --perturb --scene
    --disturb`` would."""
    from dial.disturb import parse_disturbance
    from dial.engine import RunOptions, run  # in the worker: the parent needs no MuJoCo
    from dial.parser.check import load
    from dial.scene import load_scene_names

    script = load(trial.script, loader=load_scene_names, display=trial.display, scene=trial.scene)
    disturb = tuple(parse_disturbance(d) for d in trial.disturb)  # texts cross the wire
    options = RunOptions(trial.tick, seed=trial.seed, perturb_mm=trial.perturb_mm, disturb=disturb)
    recorder = None
    if trial.dataset is not None:
        from dial.dataset.recorder import Recorder

        request = trial.dataset
        name = Path(trial.display).name
        recorder = Recorder(name, request.fps, request.cameras, trial.perturb_mm)
        options.observers.append(recorder)
    result = run(script, options)
    summary = result.summary
    error = str(summary.error) if summary.error is not None else None
    episode = None if recorder is None else recorder.episode
    if episode is not None and trial.dataset is not None and trial.dataset.successful_only:
        episode = episode if result.ok else None  # nothing to send back
    return TrialRun(result.success, summary.sim_time, summary.tick_length, error, episode)


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
        report.episode,
    )


def failed_trial(trial: Trial, reason: str) -> TrialResult:
    """A trial that produced no run report: it raised, or its worker process died."""
    return TrialResult(trial.tick, trial.trial, trial.seed, False, None, None, (), reason)


def sweep(
    trials: Sequence[Trial],
    executor: Executor,
    backend: Backend = engine_backend,
    progress: ItemsDone | None = None,
    each: Each[TrialResult] | None = None,
) -> list[TrialResult]:
    """Run every trial; results come back in the order of ``trials``, whatever ran first.

    ``each(k, result)`` sees the result of ``trials[k]`` as it arrives, and its value is
    kept. With it, the trials start in plan order (a dataset writes them so, and keeps
    fewer waiting); without it, longest ticks first, so that the last trials to finish are
    short ones and the workers end together.
    """
    order = list(range(len(trials)))
    if each is None:
        order.sort(key=lambda i: (-trials[i].tick, i))
    ran = executor.map(
        functools.partial(run_trial, backend),
        [trials[i] for i in order],
        failed_trial,
        progress,
        each,
    )
    by_index = dict(zip(order, ran, strict=True))
    return [by_index[i] for i in range(len(trials))]
