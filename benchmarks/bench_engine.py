"""Engine performance, measured in one process (DESIGN 7).

Prints:
- overhead: wall time of `dial run SCRIPT` (no recording) divided by the wall time of a bare
  `mj_step` loop over the same number of physics steps on the same scene (target <= 1.25,
  goal 1.10);
- the run's real-time factor;
- the scheduler's cost per event run on the fake robot, beside an equivalent py_trees tree
  (needs the `bench` extra: pip install -e ".[bench]").

    python benchmarks/bench_engine.py [SCRIPT] [--runs N]
"""

from __future__ import annotations

import argparse
import time

import mujoco

from dial.backend.model import load_model
from dial.engine import RunOptions, run
from dial.parser import check_text, load
from dial.resources import resolve_script
from dial.scene import load_scene_names
from dial.testing import run_fake


def engine_overhead(script_arg: str) -> None:
    script = load(resolve_script(script_arg), load_scene_names)
    result = run(script, RunOptions())
    steps, wall = result.physics_steps, result.wall_time
    model = load_model(result.world.model_path)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    t0 = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(model, data)
    bare = time.perf_counter() - t0
    print(f"{script_arg}: {steps} physics steps, {result.summary.sim_time:.2f} s simulated")
    print(f"  dial run wall time     {wall:8.3f} s")
    print(f"  bare mj_step loop      {bare:8.3f} s")
    print(f"  overhead ratio         {wall / bare:8.3f}   (target <= 1.25, goal 1.10)")
    print(f"  real-time factor       {result.summary.sim_time / wall:8.2f}")
    print(f"  task succeeded         {result.ok}")


def scheduler_cost(runs: int) -> None:
    # One-tick runs of one control period each: the scheduler's own work dominates.
    defs = "".join(f'% e{i} hand_pose "p" fingers=0x{1 << (4 * i):04X}\n' for i in range(4))
    body = "@repeat {}\n{}@end\n".format(runs // 4, "".join(f"e{i} #\n" for i in range(4)))
    script = check_text(defs + body, "bench.dial")
    assert script is not None
    t0 = time.perf_counter()
    result = run_fake(script, tick=0.01, period=0.01)
    n = result.summary.outcomes["runs"]
    dial_cost = (time.perf_counter() - t0) / n
    print(f"scheduler on the fake robot: {n} event runs of one tick")
    print(f"  dial                   {dial_cost * 1e6:8.1f} us per event run")
    try:
        import py_trees
    except ImportError:
        print("  py_trees               not installed (pip install -e '.[bench]')")
        return

    class OneTick(py_trees.behaviour.Behaviour):  # type: ignore[misc]
        """Runs for one tick, like a one-tick dial run."""

        def initialise(self) -> None:
            self.ticks = 0

        def update(self) -> py_trees.common.Status:
            self.ticks += 1
            if self.ticks > 1:
                return py_trees.common.Status.SUCCESS
            return py_trees.common.Status.RUNNING

    # The same shape as the script: four one-tick events in sequence, repeated.
    block = py_trees.composites.Sequence("block", memory=True)
    block.add_children([OneTick(f"e{i}") for i in range(4)])
    root = py_trees.decorators.Repeat("repeat", block, num_success=n // 4)
    tree = py_trees.trees.BehaviourTree(root)
    t0 = time.perf_counter()
    while tree.root.status != py_trees.common.Status.SUCCESS:
        tree.tick()
    trees_cost = (time.perf_counter() - t0) / n
    print(f"  py_trees               {trees_cost * 1e6:8.1f} us per event run")
    print(f"  ratio dial / py_trees  {dial_cost / trees_cost:8.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("script", nargs="?", default="pour.dial")
    ap.add_argument("--runs", type=int, default=4000)
    args = ap.parse_args()
    engine_overhead(args.script)
    scheduler_cost(args.runs)


if __name__ == "__main__":
    main()
