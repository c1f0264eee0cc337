"""The ``dial`` command line.

Exit status: 0 success, 1 a script or run error (or a failed criterion), 2 a
usage error, 130 an interrupt.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from dial import __version__
from dial.errors import DialError, ScriptError
from dial.instructions.scene_names import SceneLoader
from dial.parser.check import Script, load
from dial.parser.fmt import format_text
from dial.parser.show import render
from dial.parser.timeline import expand
from dial.resources import resolve_script


class UsageError(DialError):
    """A command-line usage problem: exit status 2."""


EPILOG = """\
scripts resolve as a path if it exists, else as a bundled example by name
(so 'dial show pour.dial' works from any directory).

exit status: 0 ok, 1 script error (or, for fmt --check, a file that would change),
2 usage error, 130 interrupted."""


def _scene_loader() -> SceneLoader:
    from dial.scene import load_scene_names

    return load_scene_names


def _load(arg: str, scene: str | None = None) -> Script:
    return load(resolve_script(arg), _scene_loader(), scene=scene)


def _scene_option(arg: str | None) -> str | None:
    """``--scene``, resolved like ``@scene``: an existing file (from here) or a bundled name."""
    if arg is None:
        return None
    from dial.scene import bundled_scene_names

    if Path(arg).is_file():  # absolute, so that it means the same from every called script
        return str(Path(arg).resolve())
    names = bundled_scene_names()
    if arg not in names:
        raise UsageError(
            f"--scene: '{arg}' is neither a file nor a bundled scene; "
            f"bundled scenes: {', '.join(names)}"
        )
    return arg


def cmd_check(args: argparse.Namespace) -> int:
    status = 0
    for arg in args.scripts:
        try:
            script = _load(arg, _scene_option(args.scene))
        except ScriptError as e:
            print(e.render())
            n = len(e.diagnostics)
            print(f"{arg}: {n} error{'s' if n != 1 else ''}")
            status = 1
            continue
        layout = expand(script)
        print(f"{script.path}: OK ({len(script.events)} events, {layout.length} ticks)")
    return status


def cmd_show(args: argparse.Namespace) -> int:
    script = _load(args.script, _scene_option(args.scene))
    sys.stdout.write(render(script))
    return 0


def cmd_fmt(args: argparse.Namespace) -> int:
    status = 0
    for arg in args.scripts:
        path = Path(arg)
        if not path.is_file():
            raise DialError(f"no such file '{arg}' (fmt rewrites files in place, so give a path)")
        text = path.read_text(encoding="utf-8")
        formatted = format_text(text, str(path))
        if formatted == text:
            print(f"{path}: already formatted")
        elif args.check:
            print(f"{path}: would reformat")
            status = 1
        else:
            path.write_text(formatted, encoding="utf-8")
            print(f"{path}: reformatted")
    return status


def _progress(quiet: bool) -> Callable[[int, float, list[str]], None] | None:
    if quiet or not sys.stderr.isatty():
        return None

    def show(tick: int, sim_time: float, running: list[str]) -> None:
        line = f"tick {tick:4d}  t={sim_time:7.2f} s  {', '.join(running) or '-'}"
        sys.stderr.write("\r" + line[:100].ljust(100))
        sys.stderr.flush()

    return show


def _record_usage(path: str) -> None:
    """A usage error (exit 2) if ``--record path`` is not a rerun file."""
    if Path(path).suffix.lower() != ".rrd":
        raise UsageError(f"--record writes a .rrd file, not '{path}'")


def _video_usage(path: str) -> None:
    """A usage error (exit 2) if ``--video path`` cannot work here; EGL on headless Linux."""
    if sys.platform.startswith("linux"):  # offscreen on the CPU; must precede `import mujoco`
        os.environ.setdefault("MUJOCO_GL", "egl")
    from dial.recording.video import video_problem

    problem = video_problem(path)
    if problem is not None:
        raise UsageError(problem)


def _check_watching(args: argparse.Namespace) -> None:
    """Usage errors (exit 2) and a missing display (exit 1), before the run starts."""
    if args.log_states and not args.log:
        raise UsageError("--log-states writes into the log: give --log FILE.jsonl too")
    if args.record:
        _record_usage(args.record)
    if args.video:
        _video_usage(args.video)
    if args.rerun or args.viewer:
        from dial.recording.viewer import require_display

        require_display("--rerun" if args.rerun else "--viewer")


def _watchers(args: argparse.Namespace, script: Script) -> list[Any]:
    """The run's observers: state log, rerun recording or stream, video, viewer."""
    watchers: list[Any] = []
    if args.log_states:
        from dial.recording.observers import StateLog

        watchers.append(StateLog())
    if args.record or args.rerun:
        from dial.recording.observers import Recorder
        from dial.recording.rerun_sink import RerunSink

        sink = RerunSink(Path(args.record) if args.record else None, spawn=args.rerun)
        watchers.append(Recorder(sink, Path(script.path).name))
    if args.video:
        from dial.recording.video import VideoWriter

        watchers.append(VideoWriter(Path(args.video)))
    if args.viewer:
        from dial.recording.viewer import PassiveViewer

        watchers.append(PassiveViewer())
    return watchers


def cmd_run(args: argparse.Namespace) -> int:
    _check_watching(args)
    script = _load(args.script, _scene_option(args.scene))
    from dial.engine import RunOptions, run, tick_length

    log_file = open(args.log, "w", encoding="utf-8") if args.log else None  # noqa: SIM115
    options = RunOptions(
        tick=args.tick,
        speed=args.speed,
        seed=args.seed,
        perturb_mm=args.perturb,
        realtime=args.realtime or args.viewer,
        log=log_file,
        on_tick=_progress(args.quiet),
        observers=_watchers(args, script),
    )
    tick = tick_length(script, options)
    try:
        result = run(script, options)
    except KeyboardInterrupt:  # the runner has logged it and every effector holds
        if log_file is not None:
            log_file.close()
        print("dial: interrupted; every effector holds its pose", file=sys.stderr)
        return 130
    summary = {
        "ok": result.ok,
        "success": result.success,
        "sim_time": round(result.summary.sim_time, 6),
        "wall_time": round(result.wall_time, 3),
        "physics_steps": result.physics_steps,
        "ticks": result.summary.ticks,
        "tick": tick,
        "outcomes": result.summary.outcomes,
        "criteria": result.details,
        "results": result.results,
        "error": str(result.summary.error) if result.summary.error else None,
    }
    if log_file is not None:
        result.log.write("summary", **summary)
        log_file.close()
    if not args.quiet and sys.stderr.isatty():
        sys.stderr.write("\r" + " " * 100 + "\r")
    if not args.quiet:
        _print_summary(result, tick)
    if result.summary.error is not None:
        print(f"dial: {result.summary.error}", file=sys.stderr)
    if args.json:
        print(json.dumps(summary, default=float))
    return 0 if result.ok else 1


def _print_summary(result: Any, tick: float) -> None:
    from dial.recording.timeline import qualified_event

    s = result.summary
    rtf = s.sim_time / result.wall_time if result.wall_time > 0 else float("inf")
    print(f"scene {result.world.name}: {s.ticks} ticks of {tick:g} s")
    ends = result.log.of("end")
    names = [qualified_event(r) for r in ends]
    width = max([len(n) for n in names] + [5])
    for r, name in zip(ends, names, strict=True):
        note = f"  {r['message']}" if r.get("message") else ""
        print(f"  tick {r['tick']:4d}  {name:<{width}}  {r['outcome']}{note}")
    print(
        f"simulated {s.sim_time:.2f} s in {result.wall_time:.2f} s wall "
        f"(real-time factor {rtf:.1f}), {result.physics_steps} physics steps"
    )
    for name, ok in result.success.items():
        print(f"  [{'x' if ok else ' '}] {name}: {result.details[name]}")
    print("OK" if result.ok else "FAILED")


def cmd_replay(args: argparse.Namespace) -> int:
    from dial.recording.timeline import read_log, timeline

    path = Path(args.log)
    if args.record:
        _record_usage(args.record)
    if args.video:
        _video_usage(args.video)
    records = read_log(path)
    if args.record:
        from dial.recording.replay import rebuild

        frames = rebuild(records, Path(args.record), f"{path.name} (replay)", path.parent)
        print(f"{args.record}: {frames} frames rebuilt from {path}", file=sys.stderr)
    if args.video:
        from dial.recording.replay import render_video

        frames = render_video(records, Path(args.video), path.parent)
        print(f"{args.video}: {frames} frames rendered from {path}", file=sys.stderr)
    sys.stdout.write(timeline(records))
    return 0


def cmd_tune(args: argparse.Namespace) -> int:
    import math

    from dial.tune import ProcessExecutor, TuneOptions, models, parse_ticks, tune

    try:
        ticks = parse_ticks(args.ticks)
    except ValueError as e:
        raise UsageError(f"--ticks: {e}") from None
    for flag, value in (("--trials", args.trials), ("--jobs", args.jobs)):
        if value is not None and value < 1:
            raise UsageError(f"{flag} must be at least 1, got {value}")
    if args.seed < 0:
        raise UsageError(f"--seed must be 0 or more, got {args.seed}")
    if not (math.isfinite(args.perturb) and args.perturb >= 0):
        raise UsageError(f"--perturb must be 0 mm or more, got {args.perturb:g}")
    options = TuneOptions(
        script=args.script,
        scene=_scene_option(args.scene),
        ticks=ticks,
        trials=args.trials,
        perturb_mm=args.perturb,
        seed=args.seed,
        plot=Path(args.plot) if args.plot else None,
        json=args.json,
    )
    # Each worker compiles a model file once and gives each trial a copy (dial.tune.models).
    if args.executor == "process":
        if args.address is not None:
            raise UsageError("--address needs --executor ray")
        pool = ProcessExecutor(args.jobs, initializer=models.install, preload=models.PRELOAD)
        return tune(options, pool)
    from dial.tune.ray_executor import RayExecutor, RayUsageError

    try:
        executor = RayExecutor(args.address, args.jobs, initializer=models.install)
    except RayUsageError as e:
        raise UsageError(str(e)) from None
    return tune(options, executor)


def _scene_argument(p: argparse.ArgumentParser, checking: bool = False) -> None:
    what = "check names against" if checking else "run in"
    p.add_argument(
        "--scene",
        metavar="NAME_OR_PATH",
        help=f"{what} this scene instead of the script's @scene (so do the scripts it "
        "@calls): a world file path, else a bundled scene name",
    )


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="dial",
        description="Run DIAL-style tick-based timeline scripts on a simulated "
        "Utah/MIT hand on a PUMA 560.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"dial {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    p = sub.add_parser(
        "run",
        help="run a script in its scene and report the success criteria",
        description="Run a script on the simulated hand and arm. Shows live progress, then "
        "each event's outcome, the simulated and wall time and the scene's success criteria. "
        "Exit 0 when the run completes and every criterion holds, 1 on a script or run "
        "error or a failed criterion, 130 on interrupt.",
    )
    p.add_argument("script", metavar="SCRIPT", help="script path or bundled name")
    _scene_argument(p)
    p.add_argument("--tick", type=float, metavar="S", help="tick length in s (default: @tick)")
    p.add_argument("--speed", type=float, default=1.0, metavar="F", help="divide the tick by F")
    p.add_argument("--seed", type=int, default=0, metavar="N", help="seed for --perturb")
    p.add_argument(
        "--perturb",
        type=float,
        default=0.0,
        metavar="MM",
        help="displace the true object poses by MM from the believed ones (seeded direction)",
    )
    p.add_argument("--log", metavar="FILE.jsonl", help="write the event log as JSON Lines")
    p.add_argument("--json", action="store_true", help="print a JSON summary as the last line")
    p.add_argument("--quiet", action="store_true", help="no progress and no summary table")
    p.add_argument("--realtime", action="store_true", help="pace the run to wall-clock time")
    p.add_argument(
        "--log-states",
        action="store_true",
        help="also log the robot's and objects' state 25 times per simulated second, "
        "for 'dial replay --record'",
    )
    p.add_argument(
        "--record",
        metavar="FILE.rrd",
        help="write a rerun recording: geometry, body poses, joints, tendons, tactile "
        "images, event lanes (open with 'rerun FILE.rrd'; see docs/recording.md)",
    )
    p.add_argument(
        "--video",
        metavar="FILE.mp4",
        help="render the run offscreen to an .mp4 or .gif at 25 frames per simulated "
        "second (needs the 'video' extra)",
    )
    p.add_argument(
        "--rerun", action="store_true", help="stream the recording to a spawned rerun viewer"
    )
    p.add_argument("--viewer", action="store_true", help="watch in MuJoCo's viewer, in real time")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser(
        "replay",
        help="print a run's timeline from its log, or rebuild its recording or video",
        description="Print the timeline of a run from its --log: each event's start and end "
        "with tick, simulated time and outcome, contacts, conditions, messages and the "
        "criteria. With --record or --video, also rebuild a rerun recording or a video from "
        "the log's states (written by 'dial run --log FILE --log-states').",
    )
    p.add_argument("log", metavar="LOG.jsonl", help="a log written by 'dial run --log'")
    p.add_argument("--record", metavar="FILE.rrd", help="rebuild a rerun recording")
    p.add_argument(
        "--video",
        metavar="FILE.mp4",
        help="render the states to an .mp4 or .gif, one frame per state, from the camera of "
        "'dial run --video' (needs the 'video' extra)",
    )
    p.set_defaults(func=cmd_replay)

    p = sub.add_parser(
        "check",
        help="parse and check scripts without touching the simulator",
        description="Parse and check scripts. Every problem is printed as "
        "FILE:LINE:COL: message with the source line and a caret; exit 1 if any.",
    )
    p.add_argument("scripts", nargs="+", metavar="SCRIPT", help="script path or bundled name")
    _scene_argument(p, checking=True)
    p.set_defaults(func=cmd_check)

    p = sub.add_parser(
        "show",
        help="print the compiled timeline as a chart of absolute ticks",
        description="Print the compiled timeline: one lane per event on absolute ticks "
        "(counted repeats and calls expanded; an until/while loop shown once and marked "
        "as a loop; both branches of an @if from the same tick), then the sections and "
        "every run with its executing and held ticks.",
    )
    p.add_argument("script", metavar="SCRIPT", help="script path or bundled name")
    _scene_argument(p, checking=True)
    p.set_defaults(func=cmd_show)

    p = sub.add_parser(
        "fmt",
        help="re-align diagrams and definition columns in place",
        description="Re-align execution-line diagrams, definition columns and tick-ruler "
        "comments, in place. Idempotent; the result parses to the same program.",
    )
    p.add_argument("scripts", nargs="+", metavar="FILE", help="script file to format")
    p.add_argument(
        "--check", action="store_true", help="change nothing; exit 1 if a file would change"
    )
    p.set_defaults(func=cmd_fmt)

    p = sub.add_parser(
        "tune",
        help="run a script over a grid of tick lengths and find the fastest reliable one",
        description="Run the script K times at each of N tick lengths from A to B, in "
        "parallel worker processes or as Ray tasks, and print success rate and task time "
        "per tick length. "
        "Exit 0 when some tick length succeeded in every trial, 1 when none did (or the "
        "plot could not be written), 2 on a usage error. See docs/tuning.md.",
    )
    p.add_argument("script", metavar="SCRIPT", help="script path or bundled name")
    _scene_argument(p)
    p.add_argument(
        "--ticks",
        required=True,
        metavar="A:B:N",
        help="N tick lengths from A to B s inclusive, linearly spaced (e.g. 0.05:0.5:10)",
    )
    p.add_argument("--trials", type=int, default=1, metavar="K", help="trials per tick length")
    p.add_argument(
        "--perturb",
        type=float,
        default=0.0,
        metavar="MM",
        help="displace the objects by MM in a direction seeded per trial",
    )
    p.add_argument("--seed", type=int, default=0, metavar="S", help="seed of the trial seeds")
    p.add_argument(
        "--jobs",
        type=int,
        metavar="J",
        help="worker processes, or the CPUs of a local Ray (default: all cores)",
    )
    p.add_argument(
        "--executor",
        choices=("process", "ray"),
        default="process",
        help="run the trials in local worker processes (default) or as Ray tasks, "
        "needs pip install 'dial[ray]'",
    )
    p.add_argument(
        "--address",
        metavar="ADDR",
        help="with --executor ray: the Ray cluster, HOST:PORT or auto (default: "
        "RAY_ADDRESS, else a local Ray started for the sweep)",
    )
    p.add_argument("--plot", metavar="FILE.png", help="plot success rate and task time")
    p.add_argument("--json", action="store_true", help="print the table as JSON, last line")
    p.set_defaults(func=cmd_tune)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        status: int = args.func(args)
    except ScriptError as e:
        print(e.render(), file=sys.stderr)
        return 1
    except UsageError as e:
        print(f"dial: {e}", file=sys.stderr)
        return 2
    except DialError as e:
        print(f"dial: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("dial: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
    return status


if __name__ == "__main__":
    sys.exit(main())
