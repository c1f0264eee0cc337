"""`dial tune` speed-up with J worker processes, and the same sweep on a local Ray (DESIGN 7).

Runs the same sweep with `--jobs 1` and with `--jobs J` (default 2) as `dial tune` does
(spawned workers, each compiling its models once; `--method forkserver` forks them from a
server that imported the engine once instead) and prints the speed-up (target:
1.8 or more with 2 jobs on a 2-core machine). Then it runs the sweep as Ray tasks on a
local Ray with J CPUs, started for it as `dial tune --executor ray` does, and prints its
wall time beside, with the time Ray took to start apart. Every run must give the same
results. The runs are interleaved `--repeat` times and the fastest of each kind counts.

The load average is printed first: other processes on the machine take cores from the
workers. "cores busy" is the workers' CPU time over the wall time, so a speed-up below J
with fewer than J cores busy means the workers waited for CPU. How long each worker waited
for a CPU is measured (Linux, /proc/PID/schedstat: time runnable but not running), and the
speed-up is printed a second time with that wait taken out of each worker's time: the
figure for a machine with nothing else running.

    python benchmarks/bench_tune.py [SCRIPT] [--ticks A:B:N] [--trials K] [--jobs J]
                                    [--repeat N] [--method spawn|forkserver] [--no-ray]
"""

from __future__ import annotations

import argparse
import os
import resource
import tempfile
import time
from pathlib import Path

from dial.resources import resolve_script
from dial.tune import (
    ProcessExecutor,
    RayExecutor,
    Trial,
    TrialResult,
    TrialRun,
    engine_backend,
    models,
    parse_ticks,
    plan,
    sweep,
)

WAITS = "DIAL_BENCH_WAITS"  # the folder where each worker notes its clock and CPU wait


def _engine_noting_waits(trial: Trial) -> TrialRun:
    """engine_backend, then note when it ended and how long this worker has waited for CPU."""
    report = engine_backend(trial)
    waited_ns = int(Path("/proc/self/schedstat").read_text().split()[1])
    note = f"{time.perf_counter()} {waited_ns / 1e9}"  # perf_counter: one clock for all
    (Path(os.environ[WAITS]) / str(os.getpid())).write_text(note)
    return report


def _without_waits(start: float, wall: float, folder: Path) -> float:
    """The sweep's wall time with each worker's wait for a CPU taken out of its time."""
    notes = [f.read_text().split() for f in folder.iterdir()]
    ends = [(float(end) - start, float(waited)) for end, waited in notes]
    last = max(end for end, _ in ends)
    return max(end - waited for end, waited in ends) + (wall - last)  # + the pool's shutdown


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _processes(
    trials: list[Trial], jobs: int, method: str
) -> tuple[float, float, float, list[TrialResult]]:
    """Wall time, the same without the waits for CPU, workers' CPU time, and the results."""
    # One folder for every pool (set in main): a fork server keeps the environment it was
    # started with, so the folder must outlive the first pool.
    folder = Path(os.environ[WAITS])
    for note in folder.iterdir():
        note.unlink()
    cpu = _children_cpu()
    start = time.perf_counter()
    executor = ProcessExecutor(jobs, method, models.install, models.PRELOAD)
    results = sweep(trials, executor, _engine_noting_waits)
    wall = time.perf_counter() - start
    alone = _without_waits(start, wall, folder)
    return wall, alone, _children_cpu() - cpu, results  # workers are joined at shutdown


def _ray(trials: list[Trial], cpus: int) -> tuple[float, float, list[TrialResult]]:
    """Seconds to start a local Ray, seconds of the sweep on it, and the results."""
    start = time.perf_counter()
    with RayExecutor(cpus=cpus, initializer=models.install) as executor:
        started = time.perf_counter()
        results = sweep(trials, executor)
        done = time.perf_counter()
    return started - start, done - started, results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("script", nargs="?", default="lightbulb")
    parser.add_argument("--ticks", default="0.05:0.5:10")
    parser.add_argument("--trials", type=int, default=2)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--method", default="spawn", choices=("spawn", "forkserver"))
    parser.add_argument("--no-ray", action="store_true", help="only the process pool")
    args = parser.parse_args()
    waits = tempfile.TemporaryDirectory()  # lives until the process ends
    os.environ[WAITS] = waits.name  # read by the workers: set before any pool starts

    path = resolve_script(args.script)
    trials = plan(str(path.resolve()), str(path), parse_ticks(args.ticks), args.trials)
    print(f"sweep: {path}, ticks {args.ticks}, {args.trials} trials each: {len(trials)} runs")
    print(f"cores: {os.cpu_count()}, load average before: {os.getloadavg()[0]:.2f}")
    best: dict[str, float] = {}
    reference: list[TrialResult] | None = None
    for _ in range(args.repeat):
        for jobs in (1, args.jobs):
            wall, alone, cpu, results = _processes(trials, jobs, args.method)
            best[f"jobs {jobs}"] = min(wall, best.get(f"jobs {jobs}", wall))
            best[f"alone {jobs}"] = min(alone, best.get(f"alone {jobs}", alone))
            print(
                f"  --jobs {jobs:<2}          {wall:6.1f} s wall, {cpu / wall:.2f} cores busy, "
                f"{alone:.1f} s without the waits for a CPU"
            )
            reference = reference or results
            assert results == reference, "a sweep gave different results: not deterministic"
        if not args.no_ray:
            start, wall, results = _ray(trials, args.jobs)
            best["ray"] = min(wall, best.get("ray", wall))
            best["ray start"] = min(start, best.get("ray start", start))
            print(f"  --executor ray    {wall:6.1f} s wall, after {start:.1f} s to start Ray")
            assert results == reference, "Ray gave other results than the process pool"
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    speedup = best["jobs 1"] / best[f"jobs {args.jobs}"]
    print(f"speed-up of --jobs {args.jobs} over --jobs 1: {speedup:.2f}")
    alone = best["alone 1"] / best[f"alone {args.jobs}"]
    print(f"  the same without the waits for a CPU (the machine to itself): {alone:.2f}")
    if not args.no_ray:
        print(
            f"local Ray with {args.jobs} CPUs: {best['ray']:.1f} s wall "
            f"(--jobs {args.jobs}: {best[f'jobs {args.jobs}']:.1f} s), "
            f"+ {best['ray start']:.1f} s to start Ray"
        )
    print("results: identical in every run")


if __name__ == "__main__":
    main()
