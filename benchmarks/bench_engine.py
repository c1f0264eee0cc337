"""Engine performance, measured in one process (DESIGN 7).

Prints:
- overhead: wall time of `dial run SCRIPT` (no recording) divided by the wall time of a bare
  `mj_step` loop over the same physics steps on the same scene (target <= 1.25, goal 1.10).
  The bare loop replays the run's own controls from the run's own start state, so it steps
  exactly the same physics (the same contacts, the same grasp): what remains is dial's cost.
  A loop from the scene's rest state, which the robot never disturbs, is printed beside it;
- the run's real-time factor;
- the scheduler's cost per event run on the fake robot, beside an equivalent py_trees tree
  (needs the `bench` extra: pip install -e ".[bench]").

    python benchmarks/bench_engine.py [SCRIPT] [--runs N]
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

from dial.backend import driver
from dial.backend.model import load_model
from dial.engine import RunOptions, run
from dial.parser import check_text, load
from dial.resources import resolve_script
from dial.scene import load_scene_names
from dial.testing import run_fake


class _StepRecorder:
    """Stands in for the driver's ``mujoco`` module: records what each mj_step call got."""

    def __init__(self) -> None:
        self.start: np.ndarray | None = None
        self.calls: list[tuple[np.ndarray, np.ndarray, int]] = []

    def __getattr__(self, name: str) -> object:
        return getattr(mujoco, name)

    def mj_step(self, model: mujoco.MjModel, data: mujoco.MjData, nstep: int = 1) -> None:
        if self.start is None:
            spec = mujoco.mjtState.mjSTATE_INTEGRATION
            self.start = np.empty(mujoco.mj_stateSize(model, spec))
            mujoco.mj_getState(model, data, self.start, spec)
        self.calls.append((data.ctrl.copy(), data.eq_active.copy(), nstep))
        mujoco.mj_step(model, data, nstep=nstep)


def engine_overhead(script_arg: str) -> None:
    script = load(resolve_script(script_arg), load_scene_names)
    recorder = _StepRecorder()
    driver.mujoco = recorder  # type: ignore[assignment]
    try:
        result = run(script, RunOptions())
    finally:
        driver.mujoco = mujoco
    steps, wall = result.physics_steps, result.wall_time
    model = load_model(result.world.model_path)
    data = mujoco.MjData(model)
    assert recorder.start is not None
    mujoco.mj_setState(model, data, recorder.start, mujoco.mjtState.mjSTATE_INTEGRATION)
    t0 = time.perf_counter()
    for ctrl, eq_active, nstep in recorder.calls:
        data.ctrl[:] = ctrl
        data.eq_active[:] = eq_active
        mujoco.mj_step(model, data, nstep=nstep)
    replay = time.perf_counter() - t0
    same = np.array_equal(data.qpos, np.array(result.final_qpos))
    rest = mujoco.MjData(model)
    mujoco.mj_forward(model, rest)
    t0 = time.perf_counter()
    mujoco.mj_step(model, rest, nstep=steps)
    idle = time.perf_counter() - t0
    print(f"{script_arg}: {steps} physics steps, {result.summary.sim_time:.2f} s simulated")
    print(f"  dial run wall time               {wall:8.3f} s")
    print(f"  bare loop, same physics          {replay:8.3f} s   (final state identical: {same})")
    print(f"  bare loop, scene at rest         {idle:8.3f} s")
    print(f"  overhead ratio                   {wall / replay:8.3f}   (target <= 1.25, goal 1.10)")
    print(f"  overhead ratio vs scene at rest  {wall / idle:8.3f}")
    print(f"  real-time factor                 {result.summary.sim_time / wall:8.2f}")
    print(f"  task succeeded                   {result.ok}")


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
