"""``dial tune``: run the sweep with a progress bar, then print the table and the answer."""

from __future__ import annotations

import json
import shutil
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from dial.disturb import Disturbance
from dial.parser.check import load
from dial.resources import resolve_script
from dial.scene import load_scene_names
from dial.scene.of_script import check_pushes, script_world
from dial.tune.executor import Executor, ItemsDone
from dial.tune.grid import Trial, plan
from dial.tune.report import TickRow, fastest_reliable, render_table, summarise, to_json, verdict
from dial.tune.trial import Backend, TrialResult, engine_backend, sweep

if TYPE_CHECKING:
    from dial.dataset.ordered import InOrder
    from dial.dataset.plan import Request
    from dial.parser.script import Script


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
    disturb: tuple[Disturbance, ...] = ()  # dial run --disturb, parsed (each keeps its text)
    dataset: Path | None = None  # --dataset DIR: each trial an episode (docs/datasets.md)
    request: Request | None = None  # its --fps, --cameras, --successful-only


@contextmanager
def _progress_bar(total: int, stream: TextIO) -> Iterator[ItemsDone | None]:
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
    script, trials = _plan(path, options)
    start = time.perf_counter()
    with _progress_bar(len(trials), err) as progress, _episodes(options, script) as sink:
        each = None if sink is None else _writing(sink)
        results = sweep(trials, executor, backend, progress, each)
        if sink is not None:
            _said_written(sink, options, err)
    wall = time.perf_counter() - start
    where = getattr(executor, "where", "")  # e.g. "on 2 worker processes"
    print(f"dial: {len(trials)} trials in {wall:.1f} s wall {where}".rstrip(), file=err)
    if options.trials > 1 and options.perturb_mm == 0:
        print("dial: without --perturb, the trials at each tick are the same run", file=err)

    rows = summarise(results)
    scene = ""
    if options.scene:  # a world file by its name, a bundled scene as given ("allegro_panda/pour")
        file = options.scene.endswith(".toml")
        scene = f" in scene {Path(options.scene).stem if file else options.scene}"
    faults = f", {len(options.disturb)} disturbance(s)" if options.disturb else ""
    title = (
        f"{path}{scene}: {options.trials} trial{'s' if options.trials != 1 else ''} per tick, "
        f"perturb {options.perturb_mm:g} mm, seed {options.seed}{faults}"
    )
    width = shutil.get_terminal_size().columns if out.isatty() else 120
    out.write(render_table(rows, title, width))
    for line in verdict(rows):
        print(line, file=out)
    status = 0 if fastest_reliable(rows) is not None else 1
    if options.plot is not None and not _plot(rows, options.plot, title, out, err):
        status = 1
    if options.json:
        meta: dict[str, object] = {
            "script": str(path),
            "scene": options.scene,
            "trials": options.trials,
            "perturb_mm": options.perturb_mm,
            "seed": options.seed,
        }
        if options.disturb:  # absent otherwise: a sweep without faults prints what it did
            meta["disturb"] = [d.text for d in options.disturb]
        print(json.dumps(to_json(rows, **meta)), file=out)
    return status


def _plan(path: Path, options: TuneOptions) -> tuple[Script, list[Trial]]:
    """Check the script and the options as ``dial run`` would, then list the trials: an
    error never starts a sweep."""
    script = load(path, loader=load_scene_names, scene=options.scene)
    if options.disturb:
        check_pushes(options.disturb, script_world(script))
    return script, plan(
        str(path.resolve()),
        str(path),
        options.ticks,
        options.trials,
        options.seed,
        options.perturb_mm,
        options.scene,
        tuple(d.text for d in options.disturb),  # workers parse their texts
        options.request if options.dataset is not None else None,
    )


@contextmanager
def _episodes(options: TuneOptions, script: Script) -> Iterator[InOrder | None]:
    """The dataset's writer, checked against the trials' features before any runs; it
    commits what was written however the sweep ends (a failed write has rolled back)."""
    if options.dataset is None:
        yield None
        return
    from dial.dataset.ordered import InOrder
    from dial.dataset.plan import Request, expected_features
    from dial.dataset.writer import DatasetWriter

    request = options.request or Request()
    with DatasetWriter(options.dataset, fps=request.fps) as writer:
        writer.check(expected_features(script_world(script), request))
        yield InOrder(writer)


def _writing(sink: InOrder) -> Callable[[int, TrialResult], TrialResult]:
    """Hand each trial's episode to the dataset as it arrives; keep the result without it."""

    def each(k: int, result: TrialResult) -> TrialResult:
        sink.put(k, result.episode)
        return replace(result, episode=None) if result.episode is not None else result

    return each


def _said_written(sink: InOrder, options: TuneOptions, err: TextIO) -> None:
    writer = sink.writer
    left = f", {sink.skipped} unsuccessful trial(s) left out" if sink.skipped else ""
    print(
        f"dial: {sink.written} episode(s) written to {options.dataset}{left}; it holds "
        f"{writer.episodes} episodes, {writer.frames} frames",
        file=err,
    )


def _plot(rows: list[TickRow], file: Path, title: str, out: TextIO, err: TextIO) -> bool:
    """Write the plot; False, with the reason on ``err``, when it could not be written."""
    try:
        from dial.tune.plot import plot
    except ImportError:
        print("dial: --plot needs matplotlib: pip install 'dial[plot]' (or pip install "
              "matplotlib)", file=err)  # fmt: skip
        return False
    try:
        plot(rows, file, title)
    except (OSError, ValueError) as e:  # an unwritable path, an unknown file type
        print(f"dial: --plot {file}: {e}", file=err)
        return False
    print(f"plot written to {file}", file=out)
    return True
