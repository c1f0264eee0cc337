"""The ``dial`` command line: a thin layer over the Python API (:mod:`dial.api`).

Exit status: 0 success, 1 a script or run error (or a failed criterion), 2 a usage error,
130 SIGINT and 143 SIGTERM.
"""

from __future__ import annotations

import argparse
import gc
import os
import signal
import sys
from collections.abc import Sequence

from dial import __version__
from dial.cli import common, preview, remote, replay, robots, run, teach, text, tune
from dial.cli.common import Terminated
from dial.errors import DialError, OptionError, ScriptError

EPILOG = """\
scripts resolve as a path if it exists, else as a bundled example by name
(so 'dial show pour.dial' works from any directory).

exit status: 0 ok, 1 script error (or, for fmt --check, a file that would change),
2 usage error, 130 interrupted (SIGINT), 143 terminated (SIGTERM)."""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="dial",
        description="Run DIAL-style tick-based timeline scripts on a simulated robot hand and\n"
        "arm: the Utah/MIT hand on a PUMA 560, an Allegro-like hand on a Panda-like arm\n"
        "(dial robots), or a robot folder of your own (docs/robots.md).",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"dial {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    run.add_parser(sub)
    replay.add_parser(sub)
    text.add_parsers(sub)
    tune.add_parser(sub)
    teach.add_parsers(sub)
    preview.add_parser(sub)
    robots.add_parser(sub)
    remote.add_parsers(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; ``argv`` None: this process's arguments, as the ``dial``
    program (which then also ignores stop signals while Python shuts down)."""
    if argv is None:
        # What start-up makes (modules, classes, the script) lives to the exit: collecting
        # garbage among it finds none, and costs a tenth of a quick command's time. A
        # command that runs on collects again, from its work on (common.collect_from_here).
        gc.disable()
        # numpy's OpenBLAS starts a thread per core as it loads, and each spins idle for
        # about 0.1 s of CPU before it sleeps (2^28 cycles): 0.04 s of a run's or preview's
        # CPU, taken from the other core or, on a busy machine, from dial. They sleep at
        # once instead; how BLAS splits its work, and so any result, is unchanged.
        os.environ.setdefault("OPENBLAS_THREAD_TIMEOUT", "4")
    status = _main(argv)
    if argv is None:
        # Everything is written and said; a second Ctrl-C must not turn the exit status
        # into death by signal while the interpreter tears MuJoCo and trio down.
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_IGN)
        # Nor need the interpreter's last garbage collections walk all it made (0.05 s).
        gc.freeze()
        if common.EXIT_AT_ONCE:
            # A remote operator says it lost the robot within the watchdog time and a
            # second: the interpreter's teardown (MuJoCo, the solvers) takes up to a second
            # more on a loaded machine. Everything is written and closed by now.
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(status)
    return status


# The options that draw with MuJoCo (offscreen or in a window); --cameras draws a
# dataset's videos (dial run, and dial tune's workers, which inherit the environment).
_DRAWING = ("video", "viewer", "snapshot", "picture", "storyboard", "cameras")


# Commands that end soon after their start-up: the garbage collector stays off in them
# (dial run turns it on once the engine is loaded, before the scene is).
QUICK = frozenset({"check", "show", "fmt", "preview", "world", "run"})


def draws(args: argparse.Namespace) -> bool:
    """Whether the parsed command draws with MuJoCo (else ``dial`` sets MUJOCO_GL=disable)."""
    return any(getattr(args, name, None) for name in _DRAWING)


def _main(argv: Sequence[str] | None) -> int:
    args = build_parser().parse_args(argv)
    if argv is None and not draws(args):
        # Nothing is drawn: MuJoCo need not look for an OpenGL library when it loads (on
        # Linux its GLFW binding starts a Python process per library it finds, 0.1 s).
        os.environ.setdefault("MUJOCO_GL", "disable")
    if args.command not in QUICK:
        common.collect_from_here()
    try:
        status: int = args.func(args)
    except ScriptError as e:
        print(e.render(), file=sys.stderr)
        return 1
    except OptionError as e:
        print(f"dial: {e}", file=sys.stderr)
        return 2
    except DialError as e:
        print(f"dial: {e}", file=sys.stderr)
        return 1
    except Terminated:  # SIGTERM in a command that asks for it as an exception (dial tune)
        print("dial: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:  # outside a run (which turns signals into a clean stop)
        print("dial: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
    return status
