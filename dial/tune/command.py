"""``dial tune``: run the sweep with a progress bar, then print the table and the answer."""

from __future__ import annotations

import json
import shutil
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from dial.parser.check import load
from dial.resources import resolve_script
from dial.scene import load_scene_names
from dial.tune.executor import Executor, ProcessExecutor, Progress
from dial.tune.grid import plan
from dial.tune.report import fastest_reliable, render_table, summarise, to_json, verdict
from dial.tune.trial import Backend, engine_backend, sweep


@dataclass(frozen=True)
class TuneOptions:
    script: str  # a path or a bundled script's name
    ticks: tuple[float, ...]  # s
    trials: int = 1
    perturb_mm: float = 0.0
    seed: int = 0
    plot: Path | None = None
    json: bool = False
    scene: str | None = None  # dial run --scene: an absolute path or a bundled name


@contextmanager
def _progress_bar(total: int, stream: TextIO) -> Iterator[Progress | None]:
    if not stream.isatty():
        yield None
        return
    from rich.console import Console
    from rich.progress import Progress as Bar

    with Bar(console=Console(file=stream), transient=True) as bar:
        task = bar.add_task("trials", total=total)
        yield lambda done: bar.update(task, completed=done)


def tune(
    options: TuneOptions,
    executor: Executor,
    backend: Backend = engine_backend,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Run the sweep and report it: 0 if some tick length always succeeded, else 1."""
    out, err = out or sys.stdout, err or sys.stderr  # looked up now: tests replace them
    path = resolve_script(options.script)
    load(path, loader=load_scene_names, scene=options.scene)  # an error never starts a sweep
    trials = plan(
        str(path.resolve()),
        str(path),
        options.ticks,
        options.trials,
        options.seed,
        options.perturb_mm,
        options.scene,
    )
    start = time.perf_counter()
    with _progress_bar(len(trials), err) as progress:
        results = sweep(trials, executor, backend, progress)
    wall = time.perf_counter() - start
    jobs = f" on {executor.jobs} worker processes" if isinstance(executor, ProcessExecutor) else ""
    print(f"dial: {len(trials)} trials in {wall:.1f} s wall{jobs}", file=err)
    if options.trials > 1 and options.perturb_mm == 0:
        print("dial: without --perturb, the trials at each tick are the same run", file=err)

    rows = summarise(results)
    scene = f" in scene {Path(options.scene).stem}" if options.scene else ""
    title = (
        f"{path}{scene}: {options.trials} trial{'s' if options.trials != 1 else ''} per tick, "
        f"perturb {options.perturb_mm:g} mm, seed {options.seed}"
    )
    width = shutil.get_terminal_size().columns if out.isatty() else 120
    out.write(render_table(rows, title, width))
    for line in verdict(rows):
        print(line, file=out)
    status = 0 if fastest_reliable(rows) is not None else 1
    if options.plot is not None:
        try:
            from dial.tune.plot import plot
        except ImportError:
            print(
                "dial: --plot needs matplotlib: pip install 'dial[plot]' (or pip install "
                "matplotlib)",
                file=err,
            )
            status = 1
        else:
            try:
                plot(rows, options.plot, title)
            except (OSError, ValueError) as e:  # an unwritable path, an unknown file type
                print(f"dial: --plot {options.plot}: {e}", file=err)
                status = 1
            else:
                print(f"plot written to {options.plot}", file=out)
    if options.json:
        meta = {
            "script": str(path),
            "scene": options.scene,
            "trials": options.trials,
            "perturb_mm": options.perturb_mm,
            "seed": options.seed,
        }
        print(json.dumps(to_json(rows, **meta)), file=out)
    return status
