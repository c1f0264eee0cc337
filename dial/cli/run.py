"""``dial run``: a thin layer over :func:`dial.run` that shows progress and a summary."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from dial.cli.common import (
    UsageError,
    collect_from_here,
    dataset_arguments,
    dataset_request,
    load_script,
    scene_argument,
)
from dial.cli.remote import add_run_options, check_remote
from dial.scheduler.signals import EXIT_STATUS, StopRequest, catch_stop_signals

if TYPE_CHECKING:  # what a run needs loads when it runs: `dial --help` stays quick
    from dial.dataset.writer import DatasetWriter
    from dial.engine import RunResult

DESCRIPTION = (
    "Run a script on the simulated hand and arm. Shows live progress, then each event's "
    "outcome, any warnings (a DRIVE stopped at a joint limit, a tendon held at its tension "
    "limit), the simulated and wall time and the scene's success criteria. Exit 0 when "
    "the run completes and every criterion holds; 1 on a script or run error or a failed "
    "criterion; 2 on a usage error; 130 on SIGINT (Ctrl-C) and 143 on SIGTERM, after every "
    "effector holds and the log ends with 'interrupted' and 'summary'."
)


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "run",
        help="run a script in its scene and report the success criteria",
        description=DESCRIPTION,
    )
    p.add_argument("script", metavar="SCRIPT", help="script path or bundled name")
    scene_argument(p)
    p.add_argument(
        "--tick", type=float, metavar="S", help="tick length in s, 0 < S <= 60 (default: @tick)"
    )
    p.add_argument("--speed", type=float, default=1.0, metavar="F", help="divide the tick by F")
    p.add_argument("--seed", type=int, default=0, metavar="N", help="seed for --perturb (>= 0)")
    p.add_argument(
        "--perturb",
        type=float,
        default=0.0,
        metavar="MM",
        help="displace the true object poses by MM (>= 0) from the believed ones, in a "
        "direction drawn from --seed",
    )
    p.add_argument(
        "--disturb",
        action="append",
        default=[],
        metavar="SPEC",
        help="a deliberate fault, repeatable: 'push body=NAME force=FX,FY,FZ at=T for=D' "
        "(a world-frame force in N from T s for D s) or 'sense sensor=KIND:FINGER at=T "
        "[for=D]' (tactile, force or position reads as untouched); see docs/language.md",
    )
    p.add_argument("--log", metavar="FILE.jsonl", help="write the event log as JSON Lines")
    p.add_argument(
        "--save-world",
        metavar="F.toml",
        help="at the end, write the world file with every object where the world model "
        "believes it (and its size, once measured), comments kept; 'dial world F.toml' "
        "shows it and a script run in it starts from it",
    )
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
        "images, event lanes (open with 'rerun FILE.rrd'; see docs/recording.md); with "
        "--remote, the predicted robot and the reported one together",
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
    debug = p.add_argument_group(
        "debugging (docs/debugging.md)",
        "A paused run reads commands from the terminal, or line by line from stdin when it is "
        "not one: continue, tick, period, state, save FILE, quit, help.",
    )
    debug.add_argument(
        "--break",
        dest="breaks",
        action="append",
        default=[],
        metavar="EVENT|tick:N|monitor",
        help="pause before a run of EVENT starts, at the start of absolute tick N, or after a "
        "monitor fires; repeatable",
    )
    debug.add_argument("--step", action="store_true", help="pause at the start of every tick")
    debug.add_argument(
        "--save-at",
        nargs=2,
        metavar=("block:N", "FILE"),
        help="write a state file just before the N-th block the run starts (a repeated block "
        "counts each time; 'dial show' numbers the blocks)",
    )
    debug.add_argument(
        "--resume",
        metavar="FILE",
        help="go on from a state file (with its tick, seed, perturbation and disturbances); "
        "lines of the script before the saved block must be unchanged",
    )
    dataset_arguments(p, sweep=False)
    add_run_options(p)
    p.set_defaults(func=cmd_run)


def cmd_run(args: argparse.Namespace) -> int:
    # The command owns the stop signals from here to the exit: one stops the run (dial.run
    # checks the options, then the script, then runs it) or, once the run is over, is
    # ignored: a second Ctrl-C cannot cut the summary or the log short.
    check_remote(args)
    with catch_stop_signals() as stop:
        if args.remote is not None:
            collect_from_here()
            return _remote(args, stop)
        return _run(args)


def _run(args: argparse.Namespace) -> int:
    from dial import api  # the parser and the engine: not for --help

    if args.log_states and not args.log:
        raise UsageError("--log-states writes into the log: give --log FILE.jsonl too")
    save_at = _save_at(args.save_at)
    world_file = None if args.save_world is None else api.world_file(args.save_world)
    folder, fps, cameras = dataset_request(args)
    with _dataset(folder, fps) as writer:
        result = _run_api(args, save_at, writer, cameras)
    if writer is not None and folder is not None:
        _said_written(writer, folder)
    if world_file is not None:
        api.save_world(result, world_file, f"`dial run {Path(args.script).name}`")
    return _report(args, result, save_at)


def _run_api(
    args: argparse.Namespace,
    save_at: tuple[int, str] | None,
    writer: DatasetWriter | None,
    cameras: list[str],
) -> RunResult:
    # The parser and the engine (not for --help), all loaded before the collector runs again.
    from dial import api, engine  # noqa: F401

    collect_from_here()
    return api.run(
        args.script,
        scene=args.scene,
        tick=args.tick,
        speed=args.speed,
        seed=args.seed,
        perturb=args.perturb,
        disturb=args.disturb,
        log=args.log,
        log_states=args.log_states,
        record=args.record,
        video=args.video,
        rerun=args.rerun,
        viewer=args.viewer,
        realtime=args.realtime,
        progress=_progress(args.quiet),
        breaks=args.breaks,
        step=args.step,
        save_at=save_at,
        resume=args.resume,
        dataset=writer,
        cameras=cameras,
    )


@contextmanager
def _dataset(folder: str | None, fps: int | None) -> Iterator[DatasetWriter | None]:
    """``--dataset DIR``'s writer, open for the run (closing it commits the episode)."""
    if folder is None:
        yield None
        return
    from dial.dataset.writer import DatasetWriter

    with DatasetWriter(folder, fps=50 if fps is None else fps) as writer:
        yield writer


def _said_written(writer: DatasetWriter, folder: str) -> None:
    if writer.added:
        print(
            f"dial: episode {writer.episodes - 1} ({writer.last_frames} frames) written to "
            f"{folder}; it holds {writer.episodes} episodes",
            file=sys.stderr,
        )
    else:
        print(f"dial: no episode written to {folder} (the run did not finish)", file=sys.stderr)


def _report(args: argparse.Namespace, result: RunResult, save_at: tuple[int, str] | None) -> int:
    for number, target in result.saved:
        print(f"dial: saved the state before block {number} to {target}", file=sys.stderr)
    if not args.quiet and sys.stderr.isatty():
        sys.stderr.write("\r" + " " * 100 + "\r")
    if not args.quiet:
        sys.stdout.write(summary_text(result))
    stopped = result.summary.interrupted
    if stopped is not None:
        print(f"dial: interrupted by {stopped}; every effector holds its pose", file=sys.stderr)
    elif result.error is not None:
        print(f"dial: {result.error}", file=sys.stderr)
    if args.json:
        print(json.dumps(result.as_record()))
    if result.unsaved is not None:
        print(
            f"dial: save {result.unsaved}: the run started no block after it; nothing was saved",
            file=sys.stderr,
        )
    if stopped is not None:
        return EXIT_STATUS.get(stopped, 130)
    if result.unsaved is not None:
        return 1
    if save_at is not None and not result.saved:
        print(
            f"dial: --save-at block:{save_at[0]}: the run started fewer blocks; nothing was saved",
            file=sys.stderr,
        )
        return 1
    return 0 if result.ok else 1


def _remote(args: argparse.Namespace, stop: StopRequest) -> int:
    """``dial run --remote``: the options and the script checked here, then the robot's run."""
    from dial import api
    from dial.cli.run_remote import run_remote

    api.check_options(args.tick, args.speed, args.seed, args.perturb)
    script = load_script(args.script, args.scene)
    if stop.signal is not None:  # while the script was being checked
        print(f"dial: interrupted by {stop.signal}", file=sys.stderr)
        return EXIT_STATUS[stop.signal]
    return run_remote(args, script, stop, _progress(args.quiet), summary_text)


def _save_at(value: list[str] | None) -> tuple[int, str] | None:
    """``--save-at block:N FILE`` as (N, FILE)."""
    if value is None:
        return None
    where, target = value
    digits = where.removeprefix("block:")
    number = digits.isascii() and digits.isdigit() and len(digits) <= 9 and int(digits)
    if not where.startswith("block:") or not number:
        raise UsageError(f"--save-at: expected block:N FILE, N a block from 1; got '{where}'")
    return number, target


def _progress(quiet: bool) -> Callable[[int, float, list[str]], None] | None:
    if quiet or not sys.stderr.isatty():
        return None

    def show(tick: int, sim_time: float, running: list[str]) -> None:
        line = f"tick {tick:4d}  t={sim_time:7.2f} s  {', '.join(running) or '-'}"
        sys.stderr.write("\r" + line[:100].ljust(100))
        sys.stderr.flush()

    return show


def summary_text(result: RunResult) -> str:
    """The table ``dial run`` prints: each run's end, the times, the criteria (pure)."""
    from dial.recording.timeline import qualified_event

    s = result.summary
    lines = [f"scene {result.world.name}: {s.ticks} ticks of {s.tick_length:g} s"]
    ends = result.log.of("end")
    names = [qualified_event(r) for r in ends]
    width = max([len(n) for n in names] + [5])
    for r, name in zip(ends, names, strict=True):
        note = f"  {r['message']}" if r.get("message") else ""
        lines.append(f"  tick {r['tick']:4d}  {name:<{width}}  {r['outcome']}{note}")
    for r in result.log.of("warning"):  # a DRIVE stopped at a limit, a tendon held at its own
        where = f"tick {r['tick']:4d}" if "tick" in r else f"t={r['t']:.2f} s"
        lines.append(f"  {where}  warning: {r['message']}")
    for r in result.log.of("monitor"):
        lines.append(
            f"  tick {r['tick']:4d}  monitor '@on {r['condition']}' fired at "
            f"t={r['t']:.3f} s (line {r['line']})"
        )
    lines.append(_times(result))
    for name, ok in result.success.items():
        lines.append(f"  [{'x' if ok else ' '}] {name}: {result.details[name]}")
    lines.append("OK" if result.ok else "FAILED")
    return "\n".join(lines) + "\n"


def _times(result: RunResult) -> str:
    """Simulated and wall time; a resumed run's real-time factor counts from the resume."""
    s = result.summary
    resumed = result.log.of("resume")
    t = resumed[0]["t"] if resumed else 0.0
    since = t if isinstance(t, float | int) else 0.0
    span = s.sim_time - since
    factor = span / result.wall_time if result.wall_time > 0 else float("inf")
    after = f" ({span:.2f} s after resuming at {since:.2f} s)" if resumed else ""
    return (
        f"simulated {s.sim_time:.2f} s{after} in {result.wall_time:.2f} s wall "
        f"(real-time factor {factor:.1f}), {result.physics_steps} physics steps"
    )
