"""The cost of ``dial preview`` against ``dial run`` (DESIGN 6.1, 7): the ratio of wall times.

Both happen in this process, interleaved, each from the loaded script to its result (the
scene's loading included in both); the imports are done up front. The IK's memo of solved
targets is emptied before each, so that each costs what it costs a user's fresh `dial run`
or `dial preview` (the memo would otherwise serve the preview the run's solutions). The
figure is the best preview over the best run. Target for pour: at most 0.1.

    python benchmarks/bench_preview.py [SCRIPT ...] [--repeats N]
"""

from __future__ import annotations

import argparse
import time

from dial.engine import RunOptions, run
from dial.parser import load
from dial.preview import preview
from dial.resources import resolve_script
from dial.robot.memo import forget_solutions
from dial.scene import load_scene_names


def bench(script_arg: str, repeats: int) -> None:
    script = load(resolve_script(script_arg), loader=load_scene_names)
    runs, previews = [], []
    for _ in range(repeats):
        forget_solutions()
        start = time.perf_counter()
        result = run(script, RunOptions())
        runs.append(time.perf_counter() - start)
        forget_solutions()
        start = time.perf_counter()
        found = preview(script)
        previews.append(time.perf_counter() - start)
    ratio = min(previews) / min(runs)
    print(f"{script_arg}: {result.summary.sim_time:.2f} s simulated")
    print(f"  dial run               {min(runs):8.3f} s wall (best of {repeats})")
    print(f"  dial preview           {min(previews):8.3f} s wall  ({found.summary()})")
    print(f"  ratio preview / run    {ratio:8.3f}   (target <= 0.1)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("scripts", nargs="*", default=["pour.dial"])
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args()
    for script in args.scripts:
        bench(script, args.repeats)


if __name__ == "__main__":
    main()
