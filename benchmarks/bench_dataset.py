"""What writing a dataset costs (DESIGN 7: at most 1.3x a run's wall time without cameras),
and the memory of a sweep that writes one: about the same for 10 trials and for 200.

1. Pour without cameras, with and without ``--dataset``, in interleaved pairs: in this
   process (``dial.run``: the run, the recording, the stats and the files) and as whole
   ``dial run`` processes (pyarrow's import included). Ratios of medians, wall and CPU.
2. ``dial tune SCRIPT --trials N --perturb 5 --jobs 2 --dataset D`` for N = 10 and 200, each
   in a process of its own: the parent's peak resident memory (it receives every episode
   and writes them in trial order; a worker holds one episode at a time). The sweeps use
   ``reactions.dial`` at 0.1 s by default (0.1 s of wall a run; 200 pours would take 20
   minutes here; ``--script lightbulb.dial --tick 0.05`` has episodes 7x longer), and it
   prints what the episodes' arrays would take if they were held in memory.

The machine's load average is printed first: on a shared machine the wall-time ratios
move by 0.1 from one invocation to the next; the CPU-time ratios move less.

    python benchmarks/bench_dataset.py [--pairs N] [--script S] [--tick T] [--trials 10,200]
                                       [--no-cost]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# The parent's peak from /proc (VmHWM, in kB): ru_maxrss would carry over the peak of the
# process that forked it (Linux keeps it across exec).
MEMORY = """
import json, sys
from dial.cli import main
status = main(sys.argv[1:])
peak = next(int(l.split()[1]) for l in open("/proc/self/status") if l.startswith("VmHWM"))
print(json.dumps({"status": status, "parent": peak}))
"""


def _pairs(pairs: int, folder: Path) -> None:
    import dial

    script = dial.load("pour.dial")
    dial.run(script, dataset=folder / "warm")  # imports and caches, once
    plain: list[tuple[float, float]] = []
    taken: list[tuple[float, float]] = []
    for k in range(pairs):
        for kind in (plain, taken) if k % 2 == 0 else (taken, plain):
            target = folder / f"d{k}" if kind is taken else None
            wall, cpu = time.perf_counter(), time.process_time()
            dial.run(script, dataset=target)
            kind.append((time.perf_counter() - wall, time.process_time() - cpu))
    for what, i in (("wall", 0), ("CPU", 1)):
        a = statistics.median(p[i] for p in plain)
        b = statistics.median(t[i] for t in taken)
        print(f"  in process, {what:4}: {a:.3f} s without, {b:.3f} s with: ratio {b / a:.3f}")
    frames = json.loads((folder / "d0/meta/info.json").read_text())["total_frames"]
    size = sum(p.stat().st_size for p in (folder / "d0").rglob("*") if p.is_file())
    print(f"  one episode: {frames} frames, {size / 2**20:.1f} MB on disk")


def _processes(pairs: int, folder: Path) -> None:
    base = [sys.executable, "-m", "dial.cli", "run", "pour.dial", "--quiet"]
    times: dict[bool, list[float]] = {False: [], True: []}
    for k in range(pairs):
        for dataset in (False, True) if k % 2 == 0 else (True, False):
            extra = ["--dataset", str(folder / f"p{k}")] if dataset else []
            start = time.perf_counter()
            subprocess.run(base + extra, check=True, capture_output=True)
            times[dataset].append(time.perf_counter() - start)
    a, b = statistics.median(times[False]), statistics.median(times[True])
    print(f"  whole process:    {a:.3f} s without, {b:.3f} s with: ratio {b / a:.3f}")


def _memory(script: str, tick: str, trials: int, folder: Path, dataset: bool) -> dict[str, int]:
    argv = ["tune", script, "--ticks", f"{tick}:{tick}:1", "--trials", str(trials)]
    argv += ["--perturb", "5"]
    argv += ["--jobs", "2"] + (["--dataset", str(folder / f"m{trials}")] if dataset else [])
    done = subprocess.run(
        [sys.executable, "-c", MEMORY, *argv], check=True, capture_output=True, text=True
    )
    result: dict[str, int] = json.loads(done.stdout.strip().splitlines()[-1])
    return result


def _frame_bytes(features: dict[str, dict[str, object]]) -> int:
    """The bytes of one frame's arrays, as an episode holds them."""
    import numpy as np

    total = 0
    for feature in features.values():
        if feature["dtype"] != "video":
            shape = [int(n) for n in feature["shape"]]  # type: ignore[attr-defined]
            total += int(np.prod(shape)) * np.dtype(str(feature["dtype"])).itemsize
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=5, help="interleaved pairs of pour runs")
    parser.add_argument("--script", default="reactions.dial", help="the memory sweeps' script")
    parser.add_argument("--tick", default="0.1", help="the memory sweeps' tick (s)")
    parser.add_argument("--trials", default="10,200", help="the memory sweeps' trial counts")
    parser.add_argument("--no-cost", action="store_true", help="only the memory sweeps")
    args = parser.parse_args()
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"load average: {load} on {os.cpu_count()} cores")
    folder = Path(tempfile.mkdtemp(prefix="dial-bench-dataset-"))
    try:
        if not args.no_cost:
            print("the cost of --dataset on pour.dial (50 fps, no cameras; target <= 1.3):")
            _pairs(args.pairs, folder)
            _processes(max(3, args.pairs // 2), folder)
        counts = [int(n) for n in args.trials.split(",")]
        print(f"peak resident memory of `dial tune {args.script} --jobs 2 --dataset D`:")
        base = _memory(args.script, args.tick, counts[0], folder, dataset=False)
        print(f"  {counts[0]:4d} trials without --dataset: parent {base['parent'] / 1024:.0f} MB")
        peaks = {}
        for n in counts:
            got = peaks[n] = _memory(args.script, args.tick, n, folder, dataset=True)
            info = json.loads((folder / f"m{n}/meta/info.json").read_text())
            size = sum(p.stat().st_size for p in (folder / f"m{n}").rglob("*") if p.is_file())
            print(
                f"  {n:4d} trials: parent {got['parent'] / 1024:.0f} MB; "
                f"{info['total_episodes']} episodes, {info['total_frames']} frames, "
                f"{size / 2**20:.1f} MB on disk"
            )
        first, last = counts[0], counts[-1]
        info = json.loads((folder / f"m{last}/meta/info.json").read_text())
        held = info["total_frames"] * _frame_bytes(info["features"])
        ratio = peaks[last]["parent"] / peaks[first]["parent"]
        print(
            f"  ratio {last}/{first} trials, parent: {ratio:.3f} (held in memory, the {last} "
            f"episodes' arrays alone would take {held / 2**20:.0f} MB)"
        )
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
