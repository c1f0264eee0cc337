"""Engine performance, measured in one process (DESIGN 7).

Prints:
- overhead: wall time of `dial run SCRIPT` (no recording) divided by the wall time of a bare
  `mj_step` loop over the same physics steps on the same scene (target for pour.dial:
  <= 1.05; with a monitor armed through its last block: <= 1.15).
  The bare loop replays the run's own controls from the run's own start state, so it steps
  exactly the same physics (the same contacts, the same grasp): what remains is dial's cost.
  It replays on the run's own MjModel and MjData, right after the run: on a copy of its own,
  where the allocator happened to put the two moved the ratio by up to +-0.02 from one
  invocation of this script to the next.
  Runs and replays alternate K times (a noisy neighbour slows a pair alike); the median of
  the pairs' ratios is the figure, the best run over the best replay is printed beside it,
  and the ratio of process CPU times. mj_step's own speed drifts by 10-20 % over seconds on a
  shared machine, so a run and a replay seconds apart can disagree by that much; the ratio
  of a run's wall time to the time it spent inside mj_step (timed call by call, in a run of
  its own after each pair, as the timing costs time too) is measured within one span and is
  the steadiest figure; it leaves out what dial's work between physics steps costs the
  physics (its data pushed out of the caches), which the pairs include.
  A loop from the scene's rest state, which the robot never disturbs, is printed beside it;
- the run's real-time factor (goal for pour.dial: >= 20 on one core);
- for a script in the pour scene, the bare physics of that run per simulated second beside
  that of the same script in the pour scene as it was before issue 16
  (benchmarks/pour_before/), each replayed from its own run, and their ratio (target >= 3);
- the scheduler's cost per event run on the fake robot, beside an equivalent py_trees tree
  (needs the `bench` extra: pip install -e ".[bench]").

    python benchmarks/bench_engine.py [SCRIPT] [--runs N] [--repeat K] [--scene S]
"""

from __future__ import annotations

import argparse
import importlib
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import mujoco
import numpy as np

from dial.backend import driver
from dial.backend.model import load_model
from dial.engine import RunOptions, RunResult, run
from dial.parser import Script, check_text, load
from dial.resources import resolve_script
from dial.scene import World, load_scene_names, worlds_dir
from dial.testing import run_fake

engine_run = importlib.import_module("dial.engine.run")  # the module (dial.engine.run is run)
POUR_BEFORE = Path(__file__).resolve().parent / "pour_before" / "pour_before.toml"


class _StepRecorder:
    """Stands in for the driver's ``mujoco`` module: records what each mj_step call got."""

    def __init__(self) -> None:
        self.start: mujoco.MjData | None = None
        self.calls: list[tuple[np.ndarray, np.ndarray, int]] = []

    def __getattr__(self, name: str) -> object:
        return getattr(mujoco, name)

    def mj_step(self, model: mujoco.MjModel, data: mujoco.MjData, nstep: int = 1) -> None:
        if self.start is None:
            # The whole MjData, not mj_getState: restoring a state wakes every sleeping body
            # (MuJoCo 4), and the pour scene starts with its objects asleep.
            self.start = mujoco.MjData(model)
            mujoco.mj_copyData(self.start, model, data)
        self.calls.append((data.ctrl.copy(), data.eq_active.copy(), nstep))
        mujoco.mj_step(model, data, nstep=nstep)


class _Replay:
    """A recorded run's physics steps, replayed from its start state on a fresh model."""

    def __init__(self, recorder: _StepRecorder, model_path: Path) -> None:
        assert recorder.start is not None
        self.recorder = recorder
        self.model = load_model(model_path)
        self.data = mujoco.MjData(self.model)
        self.steps = sum(nstep for _, _, nstep in recorder.calls)
        self.sim_time = self.steps * self.model.opt.timestep

    def run(self, on: tuple[mujoco.MjModel, mujoco.MjData] | None = None) -> tuple[float, float]:
        """Replay once, on the replay's own model and data or ``on`` (a run's: the same
        memory, so that where the allocator put them cannot favour either side); (wall,
        process CPU) seconds."""
        model, data = on if on is not None else (self.model, self.data)
        mujoco.mj_copyData(data, model, self.recorder.start)
        t0, c0 = time.perf_counter(), time.process_time()
        for ctrl, eq_active, nstep in self.recorder.calls:
            data.ctrl[:] = ctrl
            data.eq_active[:] = eq_active
            mujoco.mj_step(model, data, nstep=nstep)
        return time.perf_counter() - t0, time.process_time() - c0


class _StepTimer(SimpleNamespace):
    """Stands in for the driver's ``mujoco`` module: adds up the time spent in mj_step."""

    def __init__(self) -> None:
        super().__init__(**vars(mujoco))
        self.seconds = 0.0

        def mj_step(model: mujoco.MjModel, data: mujoco.MjData, nstep: int = 1) -> None:
            t0 = time.perf_counter()
            mujoco.mj_step(model, data, nstep=nstep)
            self.seconds += time.perf_counter() - t0

        self.mj_step = mj_step


def _run_with(stand_in: object, script: Script) -> RunResult:
    """Run ``script`` with ``stand_in`` as the driver's ``mujoco`` module."""
    driver.mujoco = stand_in  # type: ignore[assignment]
    try:
        return run(script, RunOptions())
    finally:
        driver.mujoco = mujoco


def _run_keeping(script: Script) -> tuple[RunResult, tuple[mujoco.MjModel, mujoco.MjData]]:
    """Run ``script`` as dial run does; also return the run's model and data."""
    kept: list[tuple[mujoco.MjModel, mujoco.MjData]] = []
    original = engine_run.prepare

    def prepare(*args: Any, **kwargs: Any) -> tuple[driver.MujocoRobot, Any]:
        robot, ctx = original(*args, **kwargs)
        kept.append((robot.model, robot.data))
        return robot, ctx

    engine_run.prepare = prepare
    try:
        result = run(script, RunOptions())
    finally:
        engine_run.prepare = original
    return result, kept[0]


def _record(script: Script) -> tuple[RunResult, _Replay]:
    """One run with the step recorder (not timed: the recorder has its own cost)."""
    recorder = _StepRecorder()
    recorded = _run_with(recorder, script)
    return recorded, _Replay(recorder, recorded.world.model_path)


def engine_overhead(
    script_arg: str | Script, repeat: int, target: str = ""
) -> tuple[World, _Replay]:
    """Print the overhead figures; return the run's world and replay. Runs are deterministic,
    so every timed run steps the same physics as the recorded one."""
    if isinstance(script_arg, Script):
        script, script_arg = script_arg, Path(script_arg.path).name
    else:
        script = load(resolve_script(script_arg), loader=load_scene_names)
    _, replay = _record(script)
    model = replay.model

    # Interleaved pairs, so that a noisy neighbour slows a run and its replay alike.
    walls, replays, cpu_ratios, inside = [], [], [], []
    for _ in range(repeat):
        result, physics = _run_keeping(script)  # as dial run runs: nothing timed inside
        bare_wall, bare_cpu = replay.run(on=physics)
        walls.append(result.wall_time)
        replays.append(bare_wall)
        cpu_ratios.append(result.cpu_time / bare_cpu)
        timer = _StepTimer()  # a run of its own: timing each call costs time too
        timed = _run_with(timer, script)
        inside.append(timed.wall_time / timer.seconds)
    same = np.array_equal(physics[1].qpos, np.array(result.final_qpos))  # replayed last
    steps = result.physics_steps
    rest = mujoco.MjData(model)
    mujoco.mj_forward(model, rest)
    t0 = time.perf_counter()
    mujoco.mj_step(model, rest, nstep=steps)
    idle = time.perf_counter() - t0
    wall, bare = min(walls), min(replays)
    ratios = sorted(w / r for w, r in zip(walls, replays, strict=True))
    print(f"{script_arg}: {steps} physics steps, {result.summary.sim_time:.2f} s simulated")
    print(f"  {repeat} interleaved pairs of a run and a replay; ratio per pair:", end=" ")
    print(" ".join(f"{r:.3f}" for r in ratios))
    print(f"  dial run wall time (best)        {wall:8.3f} s")
    print(f"  bare loop, same physics (best)   {bare:8.3f} s   (final state identical: {same})")
    print(f"  bare loop, scene at rest         {idle:8.3f} s")
    median = ratios[len(ratios) // 2]
    print(f"  overhead ratio, median pair      {median:8.3f}{target}")
    print(f"  overhead ratio, best / best      {wall / bare:8.3f}")
    cpu = sorted(cpu_ratios)[len(cpu_ratios) // 2]
    print(f"  overhead ratio in CPU time       {cpu:8.3f}   (median pair)")
    own = sorted(inside)[len(inside) // 2]
    print(f"  overhead ratio within the run    {own:8.3f}   (wall / time inside mj_step; median)")
    print(f"  overhead ratio vs scene at rest  {wall / idle:8.3f}")
    goal = "   (goal for pour.dial: >= 20 on one core)" if _is_pour(result.world) else ""
    print(f"  real-time factor                 {result.summary.sim_time / wall:8.2f}{goal}")
    print(f"  task succeeded                   {result.ok}")
    return result.world, replay


def _is_pour(world: World) -> bool:
    return world.path.resolve() == (worlds_dir() / "pour.toml").resolve()


def pour_physics(script_arg: str, today: _Replay, repeat: int) -> None:
    """Bare physics per simulated second: the same script in the pour scene before issue 16
    and today, each replaying its own run; interleaved pairs, CPU time."""
    script = load(resolve_script(script_arg), loader=load_scene_names, scene=str(POUR_BEFORE))
    recorded, before = _record(script)
    costs: tuple[list[float], list[float]] = ([], [])
    for _ in range(repeat):
        for replay, cost in zip((before, today), costs, strict=True):
            cost.append(replay.run()[1] / replay.sim_time)
    ratios = sorted(b / t for b, t in zip(*costs, strict=True))
    print(f"{script_arg}: bare physics per simulated second, each scene replaying its own run")
    print(f"  {repeat} interleaved pairs; ratio per pair:", " ".join(f"{r:.2f}" for r in ratios))
    for name, replay, cost in (("before issue 16", before, costs[0]), ("today", today, costs[1])):
        ms, steps = min(cost) * 1e3, replay.steps
        print(f"  {name:<16} {ms:8.1f} ms CPU per simulated s (best; {steps} steps)")
    print(f"  ratio before / today, median pair {ratios[len(ratios) // 2]:6.2f}   (target >= 3)")
    print(f"  before: {POUR_BEFORE.parent.name}/ (succeeded: {recorded.ok})")


def watched_overhead(repeat: int) -> None:
    """The overhead with a monitor armed all through pour's last block (it never fires):
    the driver steps one physics step at a time and tests the condition after each."""
    text = resolve_script("pour.dial").read_text(encoding="utf-8")
    lines = text.splitlines()
    last = max(i for i, line in enumerate(lines) if line.startswith("retract_arm "))
    lines.insert(last + 1, "idle" + " " * 8 + "~" * (len(lines[last]) - 12))
    lines.insert(last + 2, "@on idle\n@end")
    lines.insert(
        lines.index(next(ln for ln in lines if ln.startswith("% retract_arm"))) + 1,
        "% idle tactile_contact finger=ring threshold=5mm",
    )
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "pour_watched.dial"
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
        script = load(path, loader=load_scene_names)
        print("watched spans: pour.dial with a monitor armed through its whole last block")
        engine_overhead(script, repeat, "   (target <= 1.15)")


def _fake_cost(text: str) -> tuple[float, int]:
    """Seconds per event run (or event-tick) of ``text`` on the fake robot, unpaced as
    ``dial run`` runs (the best of three), and the number of event runs."""
    script = check_text(text, "bench.dial")
    t0 = time.perf_counter()
    result = run_fake(script, tick=0.01, period=0.01, paced=False)
    return time.perf_counter() - t0, result.summary.outcomes["runs"]


def _trees_cost(root: object, done: int) -> float:
    import py_trees

    tree = py_trees.trees.BehaviourTree(root)
    t0 = time.perf_counter()
    while tree.root.status != py_trees.common.Status.SUCCESS:
        tree.tick()
    return time.perf_counter() - t0


def scheduler_cost(runs: int) -> None:
    """The runner's own cost on the fake robot beside equivalent py_trees trees (DESIGN 7)."""
    defs = "".join(f'% e{i} hand_pose "p" fingers=0x{1 << (4 * i):04X}\n' for i in range(4))
    # Workload 1: one-tick runs of one control period each: scheduling dominates.
    one = defs + "@repeat {}\n{}@end\n".format(runs // 4, "".join(f"e{i} #\n" for i in range(4)))
    # Workload 2: 10 sequential blocks, each with 4 concurrent lanes of 10 ticks.
    lanes = "".join(f"e{i} #=========\n" for i in range(4))
    blocks = defs + "@repeat {}\n{}@end\n".format(runs // 40, "\n".join([lanes] * 10))
    one_s, n1 = _fake_cost(one)
    blk_s, n2 = _fake_cost(blocks)
    per_one, per_tick = one_s / n1, blk_s / (n2 * 10)
    print("scheduler on the fake robot (unpaced, as dial run)")
    print(f"  one-tick runs:        dial {per_one * 1e6:6.2f} us per event run ({n1} runs)")
    print(f"  10 blocks x 4 x 10:   dial {per_tick * 1e6:6.2f} us per event-tick ({n2} runs)")
    try:
        import py_trees
    except ImportError:
        print("  py_trees               not installed (pip install -e '.[bench]')")
        return

    class Ticks(py_trees.behaviour.Behaviour):  # type: ignore[misc]
        """Runs for ``n`` ticks, like an n-tick dial run."""

        def __init__(self, name: str, n: int) -> None:
            super().__init__(name)
            self.n = n

        def initialise(self) -> None:
            self.ticks = 0

        def update(self) -> py_trees.common.Status:
            self.ticks += 1
            if self.ticks > self.n:
                return py_trees.common.Status.SUCCESS
            return py_trees.common.Status.RUNNING

    def one_tick_tree() -> object:
        # The same shape as the script: four one-tick events in sequence, repeated.
        block = py_trees.composites.Sequence("block", memory=True)
        block.add_children([Ticks(f"e{i}", 1) for i in range(4)])
        return py_trees.decorators.Repeat("repeat", block, num_success=n1 // 4)

    def lanes_tree() -> object:
        # Each block: four 10-tick lanes in parallel; ten blocks in sequence, repeated.
        seq = py_trees.composites.Sequence("blocks", memory=True)
        for b in range(10):
            par = py_trees.composites.Parallel(
                f"b{b}", policy=py_trees.common.ParallelPolicy.SuccessOnAll()
            )
            par.add_children([Ticks(f"e{i}", 10) for i in range(4)])
            seq.add_child(par)
        return py_trees.decorators.Repeat("repeat", seq, num_success=n2 // 40)

    # Interleaved pairs, so that a noisy neighbour slows both sides alike; median of ratios.
    ones, ticks = [], []
    for _ in range(5):
        ones.append((_fake_cost(one)[0] / n1, _trees_cost(one_tick_tree(), n1) / n1))
        ticks.append((_fake_cost(blocks)[0] / (n2 * 10), _trees_cost(lanes_tree(), n2) / (n2 * 10)))
    for label, pairs in (("one-tick runs", ones), ("10 blocks x 4 x 10", ticks)):
        ratios = sorted(d / t for d, t in pairs)
        trees = min(t for _, t in pairs)
        print(f"  {label + ':':<21} py_trees {trees * 1e6:6.2f} us (best of 5)")
        print(
            f"  ratio dial / py_trees, {label:<19} {ratios[2]:6.2f}  (median of 5 pairs; "
            "at most 0.5, goal 0.2)"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("script", nargs="?", default="pour.dial")
    ap.add_argument("--runs", type=int, default=4000, help="event runs for the scheduler cost")
    ap.add_argument("--repeat", type=int, default=5, help="timed pairs of a run and a replay")
    ap.add_argument(
        "--scene",
        help="run the script in this scene (a name or a world file; e.g. "
        "benchmarks/pour_before/pour_before.toml: today's engine on the physics of before)",
    )
    args = ap.parse_args()
    if args.scene is not None:
        path = resolve_script(args.script)
        scene = str(Path(args.scene).resolve()) if Path(args.scene).exists() else args.scene
        engine_overhead(load(path, loader=load_scene_names, scene=scene), args.repeat)
        scheduler_cost(args.runs)
        return
    goal = "   (target for pour.dial: <= 1.05)" if Path(args.script).name == "pour.dial" else ""
    world, replay = engine_overhead(args.script, args.repeat, goal)
    if _is_pour(world):
        pour_physics(args.script, replay, args.repeat)
        watched_overhead(args.repeat)
    scheduler_cost(args.runs)


if __name__ == "__main__":
    main()
