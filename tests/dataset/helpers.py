"""Episodes without physics, and small real sweeps, for the dataset tests."""

from __future__ import annotations

import hashlib
from io import StringIO
from pathlib import Path

import numpy as np

import dial
from dial.dataset.episode import Episode, EpisodeInfo
from dial.dataset.features import RobotNames, features
from dial.dataset.plan import Request
from dial.tune import Executor, TuneOptions, parse_ticks, tune

ROBOT = RobotNames(("a1", "a2"), ("h1", "h2", "h3"), ("l1", "l2"), ("f1", "f2"), (2, 3))
SWEEP = ("reactions.dial", "0.1:0.1:1")  # a cheap script: 1.7 s simulated, 0.1 s of wall


class Exact:
    """An independent observer: the arm and hand joint angles after every control period,
    and the controls applied in it, in float64."""

    def begin(self, run: dial.Watched) -> None:
        ix = run.robot.index
        self.data = run.robot.data
        self.qpos = np.concatenate([ix.arm_qpos, ix.hand_qpos])
        self.ctrl = np.concatenate([ix.arm_actuators, ix.tendon_actuators[0::2]])
        self.states = [self.data.qpos[self.qpos].copy()]
        self.controls = [self.data.ctrl[self.ctrl].copy()]

    def period(self, periods: int, tick: int) -> None:
        self.states.append(self.data.qpos[self.qpos].copy())
        self.controls.append(self.data.ctrl[self.ctrl].copy())

    def end(self, result: dial.RunResult | None) -> None:
        self.controls.append(self.data.ctrl[self.ctrl].copy())  # the hold it ends with

    def frames(self, fps: int, n: int) -> tuple[np.ndarray, np.ndarray]:
        """The states and actions a dataset at ``fps`` should hold for its ``n`` frames."""
        due = [(2 * k * 100 + fps) // (2 * fps) for k in range(n)]
        return (
            np.array([self.states[p] for p in due]),
            np.array([self.controls[p + 1] for p in due]),
        )


def fake_episode(frames: int = 20, seed: int = 0, bodies: tuple[str, ...] = ("box",)) -> Episode:
    """An episode of random frames with the features of a small made-up robot."""
    rng = np.random.default_rng(seed)
    spec = {n: f.as_json() for n, f in features(ROBOT, bodies).items()}
    columns: dict[str, np.ndarray] = {}
    for name, feature in spec.items():
        shape = tuple(feature["shape"])  # type: ignore[arg-type]
        if feature["dtype"] == "bool":
            columns[name] = np.zeros(frames, dtype=bool)
        else:
            columns[name] = rng.normal(size=(frames, *shape)).astype(np.float32)
    columns["next.done"][-1] = True
    info = EpisodeInfo(
        "fake.dial",
        "nowhere",
        0.1,
        seed,
        0.0,
        (0.0, 0.0, 0.0),
        (),
        {"done": 1},
        True,
        {},
        None,
        1.0,
    )
    return Episode(50, spec, columns, "fake.dial in scene nowhere", info)


def sweep(
    folder: Path,
    executor: Executor,
    script: str = SWEEP[0],
    ticks: str = SWEEP[1],
    trials: int = 3,
    request: Request | None = None,
) -> str:
    """``dial tune SCRIPT --ticks TICKS --trials N --perturb 5 --dataset FOLDER``; stdout."""
    out, err = StringIO(), StringIO()
    options = TuneOptions(
        script,
        parse_ticks(ticks),
        trials=trials,
        perturb_mm=5.0,
        dataset=folder,
        request=request or Request(),
    )
    tune(options, executor, out=out, err=err)
    return out.getvalue()


def digest(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` by its relative path, as a SHA-256."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }
