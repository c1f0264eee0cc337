"""Latency a person feels (issue 26, DESIGN 7): each command as a whole process, as typed.

Every row is the best of N runs of a fresh process (the ``dial`` program installed beside
this Python, else ``python -m dial.cli``), beside ``python -c pass`` on the same machine,
in wall time and (in brackets) the process's CPU time:

    python benchmarks/bench_latency.py [--repeats N] [--quick] [--no-compiled]

- ``dial --help``, ``import dial``, and ``dial check``, ``show`` and ``fmt --check`` of pour;
- ``dial run pour.dial``: the whole process minus the wall time it prints, with the IK's
  cache (docs/architecture.md, "Start-up") as a user's second run finds it, and as the
  first run ever (an empty cache);
- ``dial preview pour.dial`` as a share of ``dial run``'s whole process;
- ``dial check`` of the 300 KB mutant of explore.dial with 75,000 problems
  (benchmarks/mutant.py);
- ``dial world pour``.

The IK cache is a temporary folder (``DIAL_CACHE``), never the user's. Where Python writes
no bytecode (``PYTHONDONTWRITEBYTECODE``, as in this project's sandbox) and dial has none,
each process compiles dial's modules from source; the table is then printed a second time
for dial as an installation has it, its bytecode compiled (``python -m compileall``, what
pip does), from a temporary copy of the package. The load average is printed: on a busy
machine the figures are upper bounds. About a minute, two with the second table.
"""

from __future__ import annotations

import argparse
import compileall
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from mutant import write_mutant  # benchmarks/mutant.py

ROOT = Path(__file__).resolve().parent.parent
WALL = re.compile(r" in ([0-9.]+) s wall")


def dial_program() -> list[str]:
    """How a user starts dial: the installed program beside this Python, else the module."""
    program = Path(sys.executable).parent / "dial"
    return [str(program)] if program.is_file() else [sys.executable, "-m", "dial.cli"]


def timed(cmd: Sequence[str], env: dict[str, str]) -> tuple[float, float, str]:
    """The wall and CPU time of one process, and what it printed."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(cmd)} failed ({done.returncode}):\n{done.stderr}")
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return seconds, cpu, done.stdout


def best(cmd: Sequence[str], env: dict[str, str], repeats: int) -> tuple[float, float]:
    """The least wall time of ``repeats`` runs, and the least CPU time."""
    runs = [timed(cmd, env)[:2] for _ in range(repeats)]
    return min(w for w, _ in runs), min(c for _, c in runs)


def run_overhead(cmd: Sequence[str], env: dict[str, str], repeats: int) -> tuple[float, float]:
    """The least (whole process - printed wall time) of ``dial run``, and its whole time."""
    pairs = []
    for _ in range(repeats):
        whole, _, out = timed(cmd, env)
        found = WALL.search(out)
        if found is None:
            raise SystemExit(f"no wall time in the output of {' '.join(cmd)}:\n{out}")
        pairs.append((whole - float(found.group(1)), whole))
    return min(pairs)


def row(name: str, seconds: float | tuple[float, float], target: str = "") -> None:
    """A figure in s; with a pair, the wall time and (in brackets) the CPU time."""
    wall, cpu = seconds if isinstance(seconds, tuple) else (seconds, None)
    spent = f"({cpu:5.3f} cpu)" if cpu is not None else " " * 11
    print(f"  {name:<48} {wall:6.3f} s {spent}  {target}")


def table(env: dict[str, str], n: int, n_run: int, work: Path) -> None:
    """Every row, each command run as ``env`` says."""
    dial = dial_program()
    print(f"  (best of {n}; dial run and preview best of {n_run})")
    row("python -c pass", best([sys.executable, "-c", "pass"], env, n))
    row("python -c 'import dial'", best([sys.executable, "-c", "import dial"], env, n))
    row("dial --help", best([*dial, "--help"], env, n), "target <= 0.15 s")
    for command in (["check"], ["show"], ["fmt", "--check"]):
        seconds = best([*dial, *command, "scripts/pour.dial"], env, n)
        row(f"dial {' '.join(command)} scripts/pour.dial", seconds, "target <= 0.3 s")
    pour = [*dial, "run", "scripts/pour.dial"]
    first = dict(env, DIAL_CACHE=tempfile.mkdtemp(dir=work))  # an empty cache
    cold = run_overhead(pour, first, 1)[0]
    warm, warm_whole = run_overhead(pour, first, n_run)
    row("dial run pour: whole process - its wall time", warm, "target <= 0.5 s")
    row("  the same, the first run (an empty IK cache)", cold)
    row("  dial run pour, whole process", warm_whole)
    preview = best([*dial, "preview", "scripts/pour.dial"], first, n_run)
    row("dial preview pour, whole process", preview)
    share = preview[0] / warm_whole
    print(f"  {'  share of dial run (whole processes)':<48} {share:6.3f}   {'':11}  target <= 0.25")
    mutant = [*dial, "check", str(write_mutant(work / "scripts"))]
    row("dial check of the 300 KB, 75,000-problem mutant", best(mutant, env, n), "target <= 0.5 s")
    row("dial world pour", best([*dial, "world", "pour"], first, n))
    print(f"  load average now {os.getloadavg()[0]:.2f}")


def compiled_copy(work: Path) -> Path:
    """A copy of the ``dial`` package with its bytecode compiled, as an installation has it."""
    copy = work / "installed"
    shutil.copytree(ROOT / "dial", copy / "dial", ignore=shutil.ignore_patterns("__pycache__"))
    if not compileall.compile_dir(copy / "dial", quiet=1):
        raise SystemExit("could not compile dial's bytecode")
    return copy


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--repeats", type=int, default=5, help="runs per row (best of N)")
    ap.add_argument("--quick", action="store_true", help="3 runs per row, pour's run twice")
    ap.add_argument("--no-compiled", action="store_true", help="no second, compiled table")
    args = ap.parse_args()
    n = 3 if args.quick else args.repeats
    n_run = 2 if args.quick else 3
    work = Path(tempfile.mkdtemp(prefix="dial-latency-"))
    env = dict(os.environ, DIAL_CACHE=str(work / "cache"), PYTHONPATH=str(ROOT))
    uncompiled = bool(os.environ.get("PYTHONDONTWRITEBYTECODE")) and not any(
        (ROOT / "dial").glob("__pycache__/*.pyc")
    )
    try:
        print(f"bench_latency: {' '.join(dial_program())}, dial from {ROOT}")
        print(f"  load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
        if uncompiled:
            print("  dial as this environment runs it: compiled from source in every process")
        table(env, n, n_run, work)
        if uncompiled and not args.no_compiled:
            print("dial with its bytecode compiled, as an installation has it:")
            table(dict(env, PYTHONPATH=str(compiled_copy(work))), n, n_run, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
