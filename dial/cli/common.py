"""What the subcommands share: script loading, ``--scene``, and usage errors."""

from __future__ import annotations

import argparse
import gc
import os
import signal
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType
from typing import TYPE_CHECKING

from dial.errors import OptionError

if TYPE_CHECKING:
    from dial.parser.script import Script

UsageError = OptionError  # a usage problem: exit status 2
# Set by a command whose process must end at once after its last word (dial run --remote).
EXIT_AT_ONCE = False


def collect_from_here() -> None:
    """Let the garbage collector run again, if the ``dial`` program stopped it for its
    start-up (:func:`dial.cli.main`); what exists now is frozen: it lives to the exit, and
    the collector need not look at it again."""
    if not gc.isenabled():
        gc.freeze()
        gc.enable()


def load_script(arg: str, scene: str | None) -> Script:
    """A script argument (a path, else a bundled name), checked against ``--scene``."""
    from dial.api import load  # the parser: not for --help

    return load(arg, scene=scene)


def scene_argument(p: argparse.ArgumentParser, checking: bool = False) -> None:
    what = "check names against" if checking else "run in"
    p.add_argument(
        "--scene",
        metavar="NAME_OR_PATH",
        help=f"{what} this scene instead of the script's @scene (so do the scripts it "
        "@calls): a world file path, else a bundled scene name (another robot's as "
        "ROBOT/NAME, e.g. allegro_panda/pour)",
    )


def at_least(flag: str, value: int | None, least: int) -> None:
    if value is not None and value < least:
        raise UsageError(f"{flag} must be at least {least}, got {value}")


def plot_usage(flag: str) -> None:
    """A usage error (exit 2) if ``flag`` cannot draw here; offscreen EGL on headless Linux."""
    if sys.platform.startswith("linux"):  # must precede `import mujoco`
        os.environ.setdefault("MUJOCO_GL", "egl")
    from dial.teach.pictures import plot_problem

    problem = plot_problem(flag)
    if problem is not None:
        raise UsageError(problem)


def dataset_arguments(p: argparse.ArgumentParser, sweep: bool) -> None:
    """``--dataset DIR`` and its options, for ``dial run`` and ``dial tune``."""
    g = p.add_argument_group(
        "dataset (docs/datasets.md)",
        "Write the run"
        + ("s, one episode per trial in trial order," if sweep else "")
        + " as a LeRobot v3.0 dataset (needs the 'dataset' extra).",
    )
    g.add_argument(
        "--dataset",
        metavar="DIR",
        help="write (or append, with the same features) "
        + ("one episode per trial" if sweep else "the run as one episode")
        + " into the dataset folder DIR",
    )
    g.add_argument(
        "--fps",
        type=int,
        metavar="N",
        help="frames per simulated second, resampled from the 100 Hz control periods, "
        "1 <= N <= 100 (default 50)",
    )
    g.add_argument(
        "--cameras",
        metavar="NAMES",
        help="also record these cameras as videos, comma-separated: 'task' (the view of "
        "--video) or a camera of the scene's model (needs the 'video' extra)",
    )
    if sweep:
        g.add_argument(
            "--successful-only",
            action="store_true",
            help="write only the trials that succeeded",
        )


def dataset_request(args: argparse.Namespace) -> tuple[str | None, int | None, list[str]]:
    """``--dataset``, ``--fps``, ``--cameras``: a usage error if the last two lack the first."""
    cameras = [c.strip() for c in (args.cameras or "").split(",") if c.strip()]
    if args.dataset is None:
        given = [f for f, v in (("--fps", args.fps), ("--cameras", args.cameras)) if v is not None]
        if getattr(args, "successful_only", False):
            given.append("--successful-only")
        if given:
            raise UsageError(f"{given[0]} goes with --dataset DIR")
    if args.cameras is not None and not cameras:
        raise UsageError("--cameras: expected camera names, comma-separated")
    return args.dataset, args.fps, cameras


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where Ctrl-C would be, so that a command with workers to stop
    (``dial tune``) cleans up the same way; the command line then exits 143."""


@contextmanager
def sigterm_as_interrupt() -> Iterator[None]:
    """Raise :class:`Terminated` on SIGTERM for the duration (default: die, leaving workers)."""

    def terminate(signum: int, frame: FrameType | None) -> None:
        raise Terminated

    previous = signal.signal(signal.SIGTERM, terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
