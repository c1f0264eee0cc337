"""The Python API: load a script, run it as ``dial run`` does, read the result.

    import dial

    script = dial.load("pour.dial")           # a path, or a bundled example by name
    result = dial.run(script, tick=0.2, perturb=10, seed=3, log="pour.jsonl")
    result.ok, result.success, result.summary.sim_time

Every option of :func:`run` is an option of ``dial run`` (see docs/api.md); the command
line is a thin layer over these two functions.
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from dial.errors import DialError, OptionError
from dial.instructions.scene_names import SceneNotFoundError
from dial.parser.check import load as parse_and_check
from dial.parser.script import Script, scripts_of
from dial.resources import resolve_script
from dial.scene import load_scene_names
from dial.scene.resolve import scene_option

if TYPE_CHECKING:  # trio and MuJoCo load only to run: `import dial` and checking stay light
    from dial.dataset.plan import Request
    from dial.dataset.writer import DatasetWriter
    from dial.debug import Break, Console
    from dial.disturb import Disturbance
    from dial.engine import Observer, RunResult
    from dial.engine.state import StateFile
    from dial.scheduler.periods import Progress


def load(path: str | Path, *, scene: str | None = None) -> Script:
    """Parse and check a script: a path if it exists, else a bundled example by name.

    ``scene`` (a world file or a bundled scene name) replaces the script's ``@scene``, and
    that of every script it calls. Raises :class:`~dial.errors.ScriptError` listing every
    problem, each as ``FILE:LINE:COL: message`` with a caret.
    """
    try:
        override = None if scene is None else scene_option(scene)
    except SceneNotFoundError as e:
        raise OptionError(str(e)) from None
    return parse_and_check(resolve_script(str(path)), loader=load_scene_names, scene=override)


def check_options(
    tick: float | None, speed: float, seed: int, perturb: float, jobs: int | None = None
) -> None:
    """Raise :class:`OptionError` for a value out of its range, naming the option."""
    if tick is not None and not (math.isfinite(tick) and 0 < tick <= 60):
        raise OptionError(f"--tick must be above 0 s and at most 60 s (as @tick), got {tick:g}")
    if not (math.isfinite(speed) and speed > 0):
        raise OptionError(f"--speed must be a positive number, got {speed:g}")
    if seed < 0:
        raise OptionError(f"--seed must be 0 or more, got {seed}")
    if not (math.isfinite(perturb) and perturb >= 0):
        raise OptionError(f"--perturb must be 0 mm or more, got {perturb:g}")


def writable(path: str | Path, what: str) -> Path:
    """``path`` if a file can be written there; else a one-line :class:`DialError` saying
    why, before anything runs."""
    target = Path(path)
    folder = target.parent
    why = None
    if target.is_dir():
        why = f"'{path}' is a directory"
    elif not folder.is_dir():
        why = f"no such directory '{folder}'"
    else:  # try it: permissions, read-only file systems and /proc say no only to a write
        existed = target.exists()
        try:
            with open(target, "a", encoding="utf-8"):
                pass
        except OSError as e:
            why = f"{e.strerror or e}: '{path}'"
        else:
            if not existed:
                target.unlink()
    if why is not None:
        raise DialError(f"cannot write {what}: {why}")
    return target


@contextmanager
def log_sink(log: str | Path | TextIO | None) -> Iterator[TextIO | None]:
    if log is None or not isinstance(log, str | Path):
        yield log
        return
    try:
        sink = open(writable(log, "the log"), "w", encoding="utf-8")  # noqa: SIM115
    except OSError as e:
        raise DialError(f"cannot write the log: {e.strerror or e}: '{log}'") from None
    try:
        yield sink
    finally:
        with suppress(OSError):  # the run has reported a write error already
            sink.close()


def run(
    script: Script | str | Path,
    *,
    scene: str | None = None,
    tick: float | None = None,
    speed: float = 1.0,
    seed: int = 0,
    perturb: float = 0.0,
    disturb: Sequence[str | Disturbance] = (),
    log: str | Path | TextIO | None = None,
    log_states: bool = False,
    record: str | Path | None = None,
    video: str | Path | None = None,
    rerun: bool = False,
    viewer: bool = False,
    realtime: bool = False,
    observers: Sequence[Observer] = (),
    progress: Progress | None = None,
    breaks: Sequence[str] = (),
    step: bool = False,
    save_at: tuple[int, str | Path] | None = None,
    resume: str | Path | None = None,
    console: Console | None = None,
    dataset: str | Path | DatasetWriter | None = None,
    fps: int | None = None,
    cameras: Sequence[str] = (),
    follow_grasps: bool = True,
) -> RunResult:
    """Run a script in its scene, as ``dial run`` does, and return its :class:`RunResult`.

    ``script``: a :class:`Script` from :func:`load`, or a path or bundled name to load (with
    ``scene``). The keywords are described in docs/api.md. A stop signal (SIGINT, SIGTERM)
    ends the run cleanly: ``result.summary.interrupted``."""
    items, saved = _checked(tick, speed, seed, perturb, disturb, save_at, resume)
    check_watching(record, video, rerun, viewer)  # before the script: usage comes first
    request = _dataset_request(dataset, fps, cameras)
    script = _script(script, scene)
    from dial import engine

    stops, console = _pausing(script, breaks, step, console)
    with log_sink(log) as sink, _recording(dataset, request, script, saved, perturb) as recorder:
        options = engine.RunOptions(
            tick=tick,
            speed=speed,
            seed=seed,
            perturb_mm=perturb,
            disturb=items,
            realtime=realtime or viewer,
            log=sink,
            log_states=log_states,
            progress=progress,
            observers=[*_watchers(record, video, rerun, viewer, script), *observers, *recorder],
            breaks=stops,
            step=step,
            console=console,
            save_at=None if save_at is None else (save_at[0], Path(save_at[1])),
            resume=saved,
            follow_grasps=follow_grasps,
        )
        return engine.run(script, options)


def world_file(path: str | Path) -> Path:
    """``--save-world F.toml``'s check: a :class:`dial.OptionError` (the command line's usage
    error) if F is not ``.toml`` or cannot be written, before anything runs."""
    if Path(path).suffix.lower() != ".toml":
        raise OptionError(f"--save-world writes a world file (.toml), not '{path}'")
    try:
        return writable(path, "the world file")
    except DialError as e:
        raise OptionError(f"--save-world: {e}") from None


def save_world(result: RunResult, path: str | Path, made_by: str = "a run") -> None:
    """Write what the world model believed at the end of ``result``'s run as a world file:
    the run's own, its comments kept, each object's believed pose and size in ``[objects]``
    (``dial run --save-world``; docs/teaching.md). ``made_by`` goes into its first line."""
    from dial.teach.believed import save_world as write

    note = f"The believed world at the end of {made_by}."
    write(result.world, result.believed, world_file(path), note)


def _checked(
    tick: float | None,
    speed: float,
    seed: int,
    perturb: float,
    disturb: Sequence[str | Disturbance],
    save_at: tuple[int, str | Path] | None,
    resume: str | Path | None,
) -> tuple[list[Disturbance], StateFile | None]:
    """The option checks that need no script: ranges, SPECs, the state files."""
    from dial.disturb import parse_disturbance

    check_options(tick, speed, seed, perturb)
    if resume is not None and (tick is not None or speed != 1.0 or seed or perturb or disturb):
        raise OptionError(
            "--resume takes the tick, seed, perturbation and disturbances from the state "
            "file: give none of --tick, --speed, --seed, --perturb, --disturb with it"
        )
    try:
        items = [d if not isinstance(d, str) else parse_disturbance(d) for d in disturb]
    except DialError as e:
        raise OptionError(str(e)) from None
    if save_at is not None:
        if save_at[0] < 1:
            raise OptionError(f"--save-at block:N needs N >= 1, got {save_at[0]}")
        writable(save_at[1], "the state file")
    return items, None if resume is None else _load_state(Path(resume))


def _dataset_request(
    dataset: str | Path | DatasetWriter | None, fps: int | None, cameras: Sequence[str]
) -> Request | None:
    """What ``dataset=`` asks (checked: a usage error before anything runs), or None."""
    if dataset is None:
        if fps is not None or cameras:
            raise OptionError("fps= and cameras= go with dataset=")
        return None
    from dial.dataset.plan import Request, check_request
    from dial.dataset.writer import DatasetWriter

    if isinstance(dataset, DatasetWriter) and fps is not None and fps != dataset.fps:
        raise OptionError(f"fps={fps}: the dataset writer writes at {dataset.fps} fps")
    default = dataset.fps if isinstance(dataset, DatasetWriter) else 50
    request = Request(default if fps is None else fps, tuple(cameras))
    check_request(request)
    return request


@contextmanager
def _recording(
    dataset: str | Path | DatasetWriter | None,
    request: Request | None,
    script: Script,
    saved: StateFile | None,
    perturb_mm: float,
) -> Iterator[list[Observer]]:
    """The dataset's recorder as a list of observers (empty without ``dataset=``); a
    resumed run's perturbation is its state file's."""
    if dataset is None or request is None:
        yield []
        return
    from dial.dataset.session import recording

    moved = saved.settings.perturb_mm if saved is not None else perturb_mm
    with recording(dataset, request, script, moved) as recorder:
        yield [recorder]


def _script(script: Script | str | Path, scene: str | None) -> Script:
    if not isinstance(script, Script):
        return load(script, scene=scene)
    if scene is not None:
        raise OptionError("scene= applies when loading: pass it to dial.load()")
    return script


def _pausing(
    script: Script, breaks: Sequence[str], step: bool, console: Console | None
) -> tuple[list[Break], Console | None]:
    """The breakpoints, and where a paused run reads commands (a terminal, else stdin)."""
    if not (breaks or step):  # the debugger loads only for a run that pauses
        return [], console
    from dial.debug import LineConsole, TerminalConsole, parse_break

    stops = [parse_break(b, _event_names(script)) for b in breaks]
    if (stops or step) and console is None:
        console = TerminalConsole() if sys.stdin.isatty() else LineConsole()
    return stops, console


def _event_names(script: Script) -> set[str]:
    """The events of a script and of every script it calls (``--break EVENT``)."""
    return {name for called in scripts_of(script) for name in called.events}


def check_watching(
    record: str | Path | None, video: str | Path | None, rerun: bool, viewer: bool
) -> None:
    """What can be known about ``record``, ``video``, ``rerun`` and ``viewer`` before a run."""
    if record is not None and Path(record).suffix.lower() != ".rrd":
        raise OptionError(f"--record writes a .rrd file, not '{record}'")
    if video is not None:
        if sys.platform.startswith("linux"):  # offscreen on the CPU; before MuJoCo loads
            os.environ.setdefault("MUJOCO_GL", "egl")
        from dial.recording.video import video_problem

        problem = video_problem(str(video))
        if problem is not None:
            raise OptionError(problem)
    if rerun or viewer:
        from dial.recording.viewer import require_display

        require_display("--rerun" if rerun else "--viewer")
    if record is not None:
        writable(record, "the recording")
    if video is not None:
        writable(video, "the video")


def _watchers(
    record: str | Path | None, video: str | Path | None, rerun: bool, viewer: bool, script: Script
) -> list[Observer]:
    """The observers behind ``record``, ``video``, ``rerun`` and ``viewer`` (checked)."""
    watchers: list[Observer] = []
    if record is not None or rerun:
        from dial.parser.lanes import LanePlan
        from dial.recording.observers import Recorder
        from dial.recording.rerun_sink import RerunSink

        path = None if record is None else Path(record)
        sink = RerunSink(path, spawn=rerun)  # the lanes in script order:
        watchers.append(Recorder(sink, Path(script.path).name, plan=LanePlan.from_script(script)))
    if video is not None:
        from dial.recording.video import VideoWriter

        watchers.append(VideoWriter(Path(video)))
    if viewer:
        from dial.recording.viewer import PassiveViewer

        watchers.append(PassiveViewer())
    return watchers


def _load_state(path: Path) -> StateFile:
    from dial.engine.state import load as load_state  # MuJoCo loads only to run

    return load_state(path)
