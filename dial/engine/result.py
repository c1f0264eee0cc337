"""What a run reports: :class:`RunResult`, its summary record, and the measured criteria."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import mujoco

from dial.scene.evaluate import measure
from dial.scene.world import World
from dial.scheduler.log import EventLog, Record
from dial.scheduler.runner import Tally


@dataclass(frozen=True)
class Criteria:
    """The scene's success criteria as measured at the end: name -> held, name -> what."""

    success: dict[str, bool]
    details: dict[str, str]


def measure_criteria(
    world: World, model: mujoco.MjModel, data: mujoco.MjData, results: dict[str, dict[str, object]]
) -> Criteria:
    """Measure every criterion; one that cannot be evaluated fails and says why."""
    success: dict[str, bool] = {}
    details: dict[str, str] = {}
    for criterion in world.criteria:
        try:
            ok, detail = measure(criterion, model, data, results)
        except (ValueError, KeyError, TypeError) as e:  # a world file that cannot be measured
            ok, detail = False, f"cannot be evaluated: {e}"
        success[criterion.name] = bool(ok)
        details[criterion.name] = detail
    return Criteria(success, details)


@dataclass(frozen=True)
class RunResult:
    """One run of a script, as ``dial run`` reports it.

    ``ok``: the script ran to its end and every criterion held. ``summary``: the runner's
    figures (ticks, simulated time, outcome counts, the error or signal that stopped it).
    ``results``: the fits by point-set name. ``log``: every record, in order. ``believed``:
    what the world model believes of each object at the end (``dial run --save-world``).
    """

    summary: Tally
    world: World
    criteria: Criteria
    results: dict[str, dict[str, object]]
    wall_time: float  # s, from the first tick to the last
    cpu_time: float  # s of this process's CPU over the same span
    physics_steps: int
    log: EventLog
    final_qpos: list[float] = field(default_factory=list)
    disturbances: tuple[str, ...] = ()
    saved: tuple[tuple[int, Path], ...] = ()  # (block number, state file) written
    unsaved: Path | None = None  # a paused run's 'save FILE' that no block came to write
    # The world model at the end: body -> believed pos (m), rpy (deg), size (m) if known.
    believed: dict[str, dict[str, object]] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.summary.ok and all(self.criteria.success.values())

    @property
    def success(self) -> dict[str, bool]:
        return self.criteria.success

    @property
    def details(self) -> dict[str, str]:
        return self.criteria.details

    @property
    def error(self) -> str | None:
        return str(self.summary.error) if self.summary.error is not None else None

    @property
    def real_time_factor(self) -> float:
        return self.summary.sim_time / self.wall_time if self.wall_time > 0 else float("inf")

    def as_record(self) -> Record:
        """The ``summary`` record of the log, and ``dial run --json``'s object."""
        s = self.summary
        return {
            "ok": self.ok,
            "success": self.success,
            "sim_time": round(s.sim_time, 6),
            "wall_time": round(self.wall_time, 3),
            "physics_steps": self.physics_steps,
            "ticks": s.ticks,
            "tick": s.tick_length,
            "outcomes": s.outcomes,
            "criteria": self.details,
            "results": self.results,
            "error": self.error,
            "interrupted": s.interrupted,
            "disturbances": list(self.disturbances),
        }
