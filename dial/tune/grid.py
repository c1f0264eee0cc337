"""The plan of a sweep: the tick grid ``A:B:N`` and the seeded trials at each tick."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dial.dataset.plan import Request
from dial.parser.parse import MAX_TICK_S
from dial.units import UnitError, parse_number, parse_quantity


@dataclass(frozen=True)
class Trial:
    """One run of the script: everything a worker process needs, and nothing else.

    ``script`` is an absolute path, because a worker need not share the caller's
    working directory; ``display`` is how messages name it.
    """

    script: str
    display: str
    tick: float  # s
    trial: int  # 0 .. trials-1
    seed: int  # the seed of the --perturb direction
    perturb_mm: float
    scene: str | None = None  # replaces the script's @scene, as dial run --scene
    disturb: tuple[str, ...] = ()  # dial run --disturb SPECs, the same in every trial
    dataset: Request | None = None  # record the run as a dataset's episode


def parse_ticks(text: str) -> tuple[float, ...]:
    """``A:B:N``: N tick lengths from A to B inclusive, linearly spaced, in s.

    A and B accept time units (``50ms:500ms:10``). Raises ValueError with a
    message that says what was expected.
    """
    parts = text.split(":")
    if len(parts) != 3:
        raise ValueError(f"expected A:B:N (e.g. 0.05:0.5:10), got '{text}'")
    try:
        low, high = (parse_quantity(p.strip(), "time", "s") for p in parts[:2])
        count = parse_number(parts[2].strip())
    except UnitError as e:
        raise ValueError(f"{e} in '{text}'") from None
    if not (count.is_integer() and count >= 1):
        raise ValueError(f"N must be a whole number of at least 1, got '{parts[2]}'")
    if not 0 < low <= high <= MAX_TICK_S:
        raise ValueError(
            f"need 0 < A <= B <= {MAX_TICK_S:g} s (as @tick), got A={low:g} s and B={high:g} s"
        )
    if count == 1 and low != high:
        raise ValueError("N=1 gives one tick length, so A and B must be equal")
    # Rounding keeps linspace's last-bit noise (0.15000000000000002) out of tables and JSON.
    return tuple(round(float(t), 12) for t in np.linspace(low, high, int(count)))


def trial_seed(seed: int, trial: int) -> int:
    """The perturbation seed of trial ``trial``: independent streams from one ``--seed``.

    Every tick length uses the same K seeds, so the ticks are compared on the same
    perturbations.
    """
    return int(np.random.SeedSequence([seed, trial]).generate_state(1)[0])


def plan(
    script: str,
    display: str,
    ticks: tuple[float, ...],
    trials: int,
    seed: int = 0,
    perturb_mm: float = 0.0,
    scene: str | None = None,
    disturb: tuple[str, ...] = (),
    dataset: Request | None = None,
) -> list[Trial]:
    """Every trial of the sweep, tick by tick."""
    seeds = [trial_seed(seed, k) for k in range(trials)]
    return [
        Trial(script, display, tick, k, seeds[k], perturb_mm, scene, disturb, dataset)
        for tick in ticks
        for k in range(trials)
    ]
