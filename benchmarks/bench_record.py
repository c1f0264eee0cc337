"""The cost of ``--record`` (DESIGN 7): wall time of a run with it, divided by without.

Both runs happen in this process (rerun is imported once, up front); the recorded run's
time includes opening, writing and closing the ``.rrd`` (the scene, the lanes, the frames
and the task's measurements, as ``dial run --record`` writes them). Target: at most 1.5.
The pour run is the
one that counts; the light-bulb run simulates twice as long with little contact, so its
physics is cheap and the recording's share is larger.

    python benchmarks/bench_record.py [SCRIPT ...] [--repeats N]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from dial.engine import Observer, RunOptions, RunResult, run
from dial.parser import load
from dial.recording.lanes import LanePlan
from dial.recording.observers import Recorder
from dial.recording.rerun_sink import RerunSink
from dial.resources import resolve_script
from dial.scene import load_scene_names


def timed(script_arg: str, rrd: Path | None) -> tuple[float, RunResult]:
    script = load(resolve_script(script_arg), loader=load_scene_names)
    start = time.perf_counter()
    plan = LanePlan.from_script(script)  # as dial run --record does
    observers: list[Observer] = [Recorder(RerunSink(rrd), script_arg, plan=plan)] if rrd else []
    result = run(script, RunOptions(observers=observers))  # the recorder closes the file
    return time.perf_counter() - start, result


def bench(script_arg: str, repeats: int) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        rrd = Path(tmp) / "run.rrd"
        bare, recorded = [], []
        for _ in range(repeats):  # interleaved, so that drift in the machine hits both
            wall, result = timed(script_arg, None)
            bare.append(wall)
            recorded.append(timed(script_arg, rrd)[0])
        size = rrd.stat().st_size / 1e6
    sim = result.summary.sim_time
    print(f"{script_arg}: {sim:.2f} s simulated, {result.physics_steps} physics steps")
    print(f"  without --record       {min(bare):8.3f} s wall (best of {repeats})")
    print(f"  with --record          {min(recorded):8.3f} s wall  ({size:.1f} MB .rrd)")
    print(f"  overhead ratio         {min(recorded) / min(bare):8.3f}   (target <= 1.5)")
    print(f"  task succeeded         {result.ok}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("scripts", nargs="*", default=["pour.dial", "lightbulb.dial"])
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args()
    for script in args.scripts:
        bench(script, args.repeats)


if __name__ == "__main__":
    main()
