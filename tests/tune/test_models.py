"""A sweep worker's model cache: one compile per model file, the same results."""

from __future__ import annotations

import pytest

from dial.backend import model
from dial.resources import resolve_script
from dial.tune import engine_backend, models, plan, run_trial


def test_a_worker_compiles_each_model_once_and_its_trials_give_the_same_results(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(model, "_compiled", None)  # undone after the test
    path = resolve_script("lightbulb")
    # --perturb moves the lamp, a fixed body, in the model: each trial needs its own copy.
    trials = plan(str(path), "lightbulb.dial", (0.05,), 2, perturb_mm=5)
    fresh = [run_trial(engine_backend, t) for t in trials]
    models.install()
    models.install()  # a Ray worker installs it before every task
    assert [run_trial(engine_backend, t) for t in trials] == fresh
    # The scene, and the robot alone for the two IK solvers, were each compiled once.
    assert model.compiled_count() == 2
    assert all(r.error is None for r in fresh)
