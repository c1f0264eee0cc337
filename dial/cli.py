"""The ``dial`` command line.

Exit status: 0 success, 1 a script or run error (or a failed criterion), 2 a
usage error, 130 an interrupt.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from dial import __version__
from dial.errors import DialError, ScriptError
from dial.instructions.scene_names import SceneLoader
from dial.parser.check import Script, load
from dial.parser.fmt import format_text
from dial.parser.show import render
from dial.parser.timeline import expand
from dial.resources import resolve_script

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
