"""Latency a person feels (issue 26, DESIGN 7): each command as a whole process, as typed.

Every row is the best of N runs of a fresh process (the ``dial`` program installed beside
this Python, else ``python -m dial.cli``), beside ``python -c pass`` on the same machine,
in wall time and (in brackets) the process's CPU time:

    python benchmarks/bench_latency.py [--repeats N] [--quick] [--no-compiled] [--against DIR]

- ``dial --help``, ``import dial``, and ``dial check``, ``show`` and ``fmt --check`` of pour;
- ``dial run pour.dial``: the whole process minus the wall time it prints, with the IK's
  cache (docs/architecture.md, "Start-up") as a user's second run finds it, and as the
  first run ever (an empty cache); and a one-tick script's whole run, whose CPU time is
  that overhead without the load's part;
- ``dial preview pour.dial`` as a share of ``dial run``'s whole process, in wall time and
  in CPU time (both are one busy thread: on a loaded machine the CPU share is the steadier);
- ``dial check`` of the 300 KB mutant of explore.dial with 75,000 problems
  (benchmarks/mutant.py);
- ``dial world pour``.

``--against DIR`` runs every row also with the dial of another checkout (an earlier commit,
say), alternating the two, and prints both: on a busy machine their ratio says more than
either figure. The IK cache is a temporary folder (``DIAL_CACHE``), never the user's. Where
Python writes no bytecode (``PYTHONDONTWRITEBYTECODE``, as in this project's sandbox) and
dial has none, each process compiles dial's modules from source; the table is then printed
a second time for dial as an installation has it, its bytecode compiled (``python -m
compileall``, what pip does) in a temporary copy of the package. The load average is
printed: on a busy machine the figures are upper bounds. About a minute per table on a
quiet machine.
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
from dataclasses import dataclass
from pathlib import Path

from mutant import write_mutant  # benchmarks/mutant.py

ROOT = Path(__file__).resolve().parent.parent
WALL = re.compile(r" in ([0-9.]+) s wall")
ONE_TICK = '@scene pour\n@tick 0.25\n% pit_top hand_pose "knob_open"\npit_top #\n'
Figure = tuple[float, float | None]  # wall time, CPU time (None: not measured)


@dataclass
class Side:
    """A dial to measure: its checkout (the commands' folder) and its environment."""

    root: Path
    env: dict[str, str]


def dial_program() -> list[str]:
    """How a user starts dial: the installed program beside this Python, else the module."""
    program = Path(sys.executable).parent / "dial"
    return [str(program)] if program.is_file() else [sys.executable, "-m", "dial.cli"]


def timed(cmd: Sequence[str], side: Side) -> tuple[float, float, str]:
    """The wall and CPU time of one process, and what it printed."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(cmd, env=side.env, cwd=side.root, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(cmd)} failed ({done.returncode}):\n{done.stderr}")
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return seconds, cpu, done.stdout


def best(cmd: Sequence[str], sides: list[Side], repeats: int) -> list[Figure]:
    """For each side, the least wall time of ``repeats`` runs and the least CPU time; the
    sides take turns, so that a change of load touches them alike."""
    runs: list[list[tuple[float, float]]] = [[] for _ in sides]
    for _ in range(repeats):
        for times, side in zip(runs, sides, strict=True):
            times.append(timed(cmd, side)[:2])
    return [(min(w for w, _ in t), min(c for _, c in t)) for t in runs]


def run_overhead(
    cmd: Sequence[str], sides: list[Side], repeats: int
) -> list[tuple[float, float, float]]:
    """For each side, the least (whole process - printed wall time) of ``dial run``, that
    run's whole time, and the least CPU time of the whole process."""
    found: list[list[tuple[float, float, float]]] = [[] for _ in sides]
    for _ in range(repeats):
        for runs, side in zip(found, sides, strict=True):
            whole, cpu, out = timed(cmd, side)
            wall = WALL.search(out)
            if wall is None:
                raise SystemExit(f"no wall time in the output of {' '.join(cmd)}:\n{out}")
            runs.append((whole - float(wall.group(1)), whole, cpu))
    return [(*min((o, w) for o, w, _ in runs), min(c for _, _, c in runs)) for runs in found]


def row(name: str, figures: Sequence[Figure | float], target: str = "", unit: str = "s") -> None:
    """Figures (in s): wall time and (in brackets) CPU time, one column per side."""
    cells = []
    for figure in figures:
        wall, cpu = figure if isinstance(figure, tuple) else (figure, None)
        spent = f"({cpu:5.3f} cpu)" if cpu is not None else " " * 11
        cells.append(f"{wall:6.3f} {unit:1} {spent}")
    print(f"  {name:<48} {'   '.join(cells)}  {target}")


def table(sides: list[Side], n: int, n_run: int, work: Path) -> None:
    """Every row, each command run by each side."""
    dial = dial_program()
    print(f"  (best of {n}; dial run and preview best of {n_run})")
    row("python -c pass", best([sys.executable, "-c", "pass"], sides, n))
    row("python -c 'import dial'", best([sys.executable, "-c", "import dial"], sides, n))
    row("dial --help", best([*dial, "--help"], sides, n), "target <= 0.15 s")
    for command in (["check"], ["show"], ["fmt", "--check"]):
        figures = best([*dial, *command, "scripts/pour.dial"], sides, n)
        row(f"dial {' '.join(command)} scripts/pour.dial", figures, "target <= 0.3 s")
    fresh = [Side(s.root, dict(s.env, DIAL_CACHE=tempfile.mkdtemp(dir=work))) for s in sides]
    pour = [*dial, "run", "scripts/pour.dial"]
    cold = run_overhead(pour, fresh, 1)  # the cache folders are empty
    warm = run_overhead(pour, fresh, n_run)
    row("dial run pour: whole process - its wall time", [w[0] for w in warm], "target <= 0.5 s")
    row("  the same, the first run (an empty IK cache)", [c[0] for c in cold])
    row("  dial run pour, whole process", [(w[1], w[2]) for w in warm])
    # A run's start-up and exit with next to no run: its CPU time is the overhead above
    # without what the load adds to the wall time.
    one = work / "one_tick.dial"
    one.write_text(ONE_TICK)
    row("  dial run of a one-tick pour script, whole", best([*dial, "run", str(one)], fresh, n))
    preview = best([*dial, "preview", "scripts/pour.dial"], fresh, n_run)
    row("dial preview pour, whole process", preview)
    shares = [p[0] / w[1] for p, w in zip(preview, warm, strict=True)]
    row("  share of dial run (whole processes)", shares, "target <= 0.25", unit="")
    # Both are one busy thread: their CPU times are what a quiet machine's wall times are.
    shares = [(p[1] or 0.0) / w[2] for p, w in zip(preview, warm, strict=True)]
    row("  the same in CPU time (load-independent)", shares, unit="")
    mutant = [*dial, "check", str(write_mutant(work / "scripts"))]
    figures = best(mutant, sides, n)
    row("dial check of the 300 KB, 75,000-problem mutant", figures, "target <= 0.5 s")
    row("dial world pour", best([*dial, "world", "pour"], fresh, n))
    print(f"  load average now {os.getloadavg()[0]:.2f}")


def compiled_copy(root: Path, work: Path) -> Path:
    """A copy of ``root``'s ``dial`` package with its bytecode compiled, as installed."""
    copy = Path(tempfile.mkdtemp(dir=work))
    shutil.copytree(root / "dial", copy / "dial", ignore=shutil.ignore_patterns("__pycache__"))
    if not compileall.compile_dir(copy / "dial", quiet=1):
        raise SystemExit("could not compile dial's bytecode")
    return copy


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--repeats", type=int, default=5, help="runs per row (best of N)")
    ap.add_argument("--quick", action="store_true", help="3 runs per row, pour's run twice")
    ap.add_argument("--no-compiled", action="store_true", help="no second, compiled table")
    ap.add_argument("--against", type=Path, metavar="DIR", help="another checkout to compare")
    args = ap.parse_args()
    n = 3 if args.quick else args.repeats
    n_run = 2 if args.quick else 3
    work = Path(tempfile.mkdtemp(prefix="dial-latency-"))
    roots = [ROOT] if args.against is None else [ROOT, args.against.resolve()]
    sides = [Side(r, dict(os.environ, DIAL_CACHE=str(work), PYTHONPATH=str(r))) for r in roots]
    uncompiled = bool(os.environ.get("PYTHONDONTWRITEBYTECODE")) and not any(
        (ROOT / "dial").glob("__pycache__/*.pyc")
    )
    try:
        print(f"bench_latency: {' '.join(dial_program())}; dial from {', '.join(map(str, roots))}")
        print(f"  load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
        if uncompiled:
            print("  dial as this environment runs it: compiled from source in every process")
        table(sides, n, n_run, work)
        if uncompiled and not args.no_compiled:
            print("dial with its bytecode compiled, as an installation has it:")
            for side in sides:
                side.env["PYTHONPATH"] = str(compiled_copy(side.root, work))
            table(sides, n, n_run, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
