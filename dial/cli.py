"""The ``dial`` command line.

Exit status: 0 success, 1 a script or run error (or a failed criterion), 2 a
usage error, 130 an interrupt.
"""

from __future__ import annotations

import argparse
import json
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


def _load(arg: str) -> Script:
    return load(resolve_script(arg), _scene_loader())


def cmd_check(args: argparse.Namespace) -> int:
    status = 0
    for arg in args.scripts:
        try:
            script = _load(arg)
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
    script = _load(args.script)
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


def cmd_run(args: argparse.Namespace) -> int:
    for flag in ("record", "video", "rerun", "viewer"):
        if getattr(args, flag):
            raise UsageError(f"--{flag} is reserved for the recording work and not available yet")
    script = _load(args.script)
    from dial.engine import RunOptions, run, tick_length

    log_file = open(args.log, "w", encoding="utf-8") if args.log else None  # noqa: SIM115
    options = RunOptions(
        tick=args.tick,
        speed=args.speed,
        seed=args.seed,
        perturb_mm=args.perturb,
        realtime=args.realtime,
        log=log_file,
        on_tick=_progress(args.quiet),
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
    s = result.summary
    rtf = s.sim_time / result.wall_time if result.wall_time > 0 else float("inf")
    print(f"scene {result.world.name}: {s.ticks} ticks of {tick:g} s")
    ends = result.log.of("end")
    width = max([len(r["event"]) for r in ends] + [5])
    for r in ends:
        note = f"  {r['message']}" if r.get("message") else ""
        print(f"  tick {r['tick']:4d}  {r['event']:<{width}}  {r['outcome']}{note}")
    print(
        f"simulated {s.sim_time:.2f} s in {result.wall_time:.2f} s wall "
        f"(real-time factor {rtf:.1f}), {result.physics_steps} physics steps"
    )
    for name, ok in result.success.items():
        print(f"  [{'x' if ok else ' '}] {name}: {result.details[name]}")
    print("OK" if result.ok else "FAILED")


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
    for flag, what in (
        ("--record", "FILE.rrd"),
        ("--video", "FILE.mp4"),
    ):
        p.add_argument(flag, metavar=what, help="reserved: comes with the recording work")
    p.add_argument("--rerun", action="store_true", help="reserved: comes with the recording work")
    p.add_argument("--viewer", action="store_true", help="reserved: comes with the recording work")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser(
        "check",
        help="parse and check scripts without touching the simulator",
        description="Parse and check scripts. Every problem is printed as "
        "FILE:LINE:COL: message with the source line and a caret; exit 1 if any.",
    )
    p.add_argument("scripts", nargs="+", metavar="SCRIPT", help="script path or bundled name")
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
