"""`dial tune` speed-up with J worker processes (DESIGN 7).

Runs the same sweep with `--jobs 1` and with `--jobs J` (default 2) and prints the wall
times and the speed-up (target: 1.6 or more with 2 jobs on a 2-core machine). It also runs
J jobs with the `forkserver` start method beside the default `spawn`, and checks that every
run gives the same results. The load average is printed first: other processes on the
machine take cores from the workers. "cores busy" is the workers' CPU time over the wall
time, so a speed-up below J with fewer than J cores busy means the workers waited for CPU.

    python benchmarks/bench_tune.py [SCRIPT] [--ticks A:B:N] [--trials K] [--jobs J]
"""

from __future__ import annotations

import argparse
import os
import resource
import time

from dial.resources import resolve_script
from dial.tune import ProcessExecutor, Trial, TrialResult, parse_ticks, plan, sweep


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _timed(trials: list[Trial], jobs: int, method: str) -> tuple[float, float, list[TrialResult]]:
    cpu = _children_cpu()
    start = time.perf_counter()
    results = sweep(trials, ProcessExecutor(jobs, method))
    wall = time.perf_counter() - start
    return wall, _children_cpu() - cpu, results  # workers are joined when the pool shuts down


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("script", nargs="?", default="lightbulb")
    parser.add_argument("--ticks", default="0.05:0.5:10")
    parser.add_argument("--trials", type=int, default=2)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()

    path = resolve_script(args.script)
    trials = plan(str(path.resolve()), str(path), parse_ticks(args.ticks), args.trials)
    print(f"sweep: {path}, ticks {args.ticks}, {args.trials} trials each: {len(trials)} runs")
    print(f"cores: {os.cpu_count()}, load average before: {os.getloadavg()[0]:.2f}")
    runs = [(1, "spawn"), (args.jobs, "spawn"), (args.jobs, "forkserver")]
    walls: dict[tuple[int, str], float] = {}
    reference: list[TrialResult] | None = None
    for _ in range(args.repeat):
        for jobs, method in runs:
            wall, cpu, results = _timed(trials, jobs, method)
            walls[jobs, method] = min(wall, walls.get((jobs, method), wall))
            busy = f"{cpu / wall:.2f}" if method == "spawn" else "n/a"
            print(f"  --jobs {jobs} ({method:10s}): {wall:6.1f} s wall, {busy} cores busy")
            reference = reference or results
            assert results == reference, "a sweep gave different results: not deterministic"
    serial = walls[1, "spawn"]
    for method in ("spawn", "forkserver"):
        speedup = serial / walls[args.jobs, method]
        print(f"speed-up of --jobs {args.jobs} over --jobs 1 ({method}): {speedup:.2f}")
    print("results: identical in every run")


if __name__ == "__main__":
    main()
