"""``dial run SCRIPT --remote URL``: the operator's run, shown as ``dial run`` shows one."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

from dial.api import log_sink
from dial.parser.script import Script
from dial.scheduler.signals import EXIT_STATUS, StopRequest

if TYPE_CHECKING:
    from dial.engine import RunResult

Progress = Callable[[int, float, list[str]], None]


def run_remote(
    args: argparse.Namespace,
    script: Script,
    stop: StopRequest,
    progress: Progress | None,
    summary_text: Callable[[RunResult], str],
) -> int:
    """Run at the robot; print the summary and criteria it reports; the exit status."""
    from dial.cli import common
    from dial.engine.run import RunOptions, tick_length
    from dial.remote.serve import run_remote as operate

    common.EXIT_AT_ONCE = True  # the program's main() ends the process at once afterwards
    tick = tick_length(script, RunOptions(tick=args.tick, speed=args.speed))
    with log_sink(args.log) as sink:
        remote = operate(args, script, tick, sink, stop, progress)
    if not args.quiet and sys.stderr.isatty():
        sys.stderr.write("\r" + " " * 100 + "\r")
    result = remote.result
    if result is not None and not args.quiet:
        sys.stdout.write(summary_text(result))
    if remote.interrupted is not None:
        print(f"dial: interrupted by {remote.interrupted}; the robot holds", file=sys.stderr)
    elif remote.message is not None:
        print(f"dial: {remote.message}", file=sys.stderr)
    elif result is not None and result.error is not None:
        print(f"dial: {result.error}", file=sys.stderr)
    if args.json:
        print(json.dumps(remote.record))
    if remote.interrupted is not None:
        return EXIT_STATUS.get(remote.interrupted, 130)
    if remote.message is not None or result is None:
        return 1
    return 0 if result.ok else 1
