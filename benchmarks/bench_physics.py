"""Physics-only cost of each scene: microseconds per ``mj_step`` and the real-time factor.

This is the floor under every run: the engine's overhead is measured against it. The robot
holds a fixed command (its initial control), so the numbers are the scene's own, with the
objects at rest as a task would find them.

    python benchmarks/bench_physics.py [--seconds S] [--repeats R]
"""

from __future__ import annotations

import argparse
import time

import mujoco

from dial.scene import load_world, worlds_dir

SCENES = ("pour", "lightbulb", "surface", "containment")


def step_time(model: mujoco.MjModel, seconds: float, repeats: int) -> tuple[float, int]:
    """Best-of-``repeats`` wall time per step (s) over ``seconds`` of sim, and the contacts."""
    data = mujoco.MjData(model)
    steps = round(seconds / model.opt.timestep)
    mujoco.mj_step(model, data, steps)  # settle first: tasks start from rest
    best, contacts = float("inf"), 0
    for _ in range(repeats):
        start = time.perf_counter()
        mujoco.mj_step(model, data, steps)
        best = min(best, (time.perf_counter() - start) / steps)
        contacts = data.ncon
    return best, contacts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="simulated time per repeat")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print(f"{'scene':<12} {'nq':>4} {'contacts':>8} {'us/step':>9} {'real-time factor':>17}")
    for name in SCENES:
        world = load_world(worlds_dir() / f"{name}.toml")
        model = mujoco.MjModel.from_xml_path(str(world.model_path))
        per_step, contacts = step_time(model, args.seconds, args.repeats)
        factor = model.opt.timestep / per_step
        print(f"{name:<12} {model.nq:>4} {contacts:>8} {per_step * 1e6:>9.1f} {factor:>17.1f}")


if __name__ == "__main__":
    main()
