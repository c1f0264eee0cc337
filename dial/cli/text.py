"""``dial check``, ``dial show`` and ``dial fmt``: the script as text, no simulator."""

from __future__ import annotations

import argparse
import os
import stat
import sys
import tempfile
from contextlib import suppress
from pathlib import Path

from dial.cli.common import load_script, scene_argument
from dial.errors import DialError, ScriptError


def add_parsers(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "check",
        help="parse and check scripts without touching the simulator",
        description="Parse and check scripts. Every problem is printed as "
        "FILE:LINE:COL: message with the source line and a caret; exit 1 if any.",
    )
    p.add_argument("scripts", nargs="+", metavar="SCRIPT", help="script path or bundled name")
    scene_argument(p, checking=True)
    p.set_defaults(func=cmd_check)

    p = sub.add_parser(
        "show",
        help="print the compiled timeline as a chart of absolute ticks",
        description="Print the compiled timeline: one lane per event on absolute ticks "
        "(counted repeats and calls expanded; an until/while loop shown once and marked "
        "as a loop; both branches of an @if from the same tick; watched spans as '~', and "
        "each @on reaction laid out after its block), then the sections, every run with its "
        "executing and held ticks, and the watched spans. A timeline too large to expand "
        "is shown compactly (each counted repeat drawn once), and says so.",
    )
    p.add_argument("script", metavar="SCRIPT", help="script path or bundled name")
    scene_argument(p, checking=True)
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


def cmd_check(args: argparse.Namespace) -> int:
    from dial.parser.timeline import length

    status = 0
    for arg in args.scripts:
        try:
            script = load_script(arg, args.scene)
        except ScriptError as e:
            print(e.render())
            n = len(e.diagnostics)
            more = ", and lines not checked" if e.cutoffs else ""
            print(f"{arg}: {n} error{'s' if n != 1 else ''}{more}")
            status = 1
            continue
        ticks = length(script)  # by arithmetic: a check never unrolls repeats
        print(f"{script.path}: OK ({len(script.events)} events, {ticks} ticks)")
    return status


def cmd_show(args: argparse.Namespace) -> int:
    from dial.parser.show import render

    script = load_script(args.script, args.scene)
    sys.stdout.write(render(script))
    return 0


def cmd_fmt(args: argparse.Namespace) -> int:
    from dial.parser.fmt import format_text

    status = 0
    for arg in args.scripts:
        path = Path(arg)
        if not path.is_file():
            raise DialError(f"no such file '{arg}' (fmt rewrites files in place, so give a path)")
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError as e:
            line = e.object[: e.start].count(b"\n") + 1
            raise DialError(
                f"{arg}:{line}: not UTF-8 text (byte {e.start + 1}); dial scripts are UTF-8"
            ) from None
        formatted = format_text(text, str(path))
        if formatted == text:
            print(f"{path}: already formatted")
        elif args.check:
            print(f"{path}: would reformat")
            status = 1
        else:
            try:
                _rewrite(path, formatted)
            except OSError as e:
                raise DialError(f"cannot rewrite {arg}: {e.strerror or e}") from None
            print(f"{path}: reformatted")
    return status


def _rewrite(path: Path, text: str) -> None:
    """Replace the file's text whole or not at all: a full disk or a Ctrl-C mid-write must
    not leave a script cut short. Written beside it, then renamed over it, mode kept; where
    no file can be made beside it (a read-only folder), written in place."""
    target = path.resolve()  # through a symlink: the link keeps pointing at the script
    if not os.access(target, os.W_OK):
        raise PermissionError(13, "Permission denied")
    try:
        fd, temp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    except OSError:
        target.write_text(text, encoding="utf-8")
        return
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.chmod(temp, stat.S_IMODE(target.stat().st_mode))
        os.replace(temp, target)
    except BaseException:
        with suppress(OSError):
            os.unlink(temp)
        raise
