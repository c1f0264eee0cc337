"""``dial tune``: a sweep of tick lengths, in parallel, for the fastest reliable one."""

from __future__ import annotations

import argparse
from pathlib import Path

from dial import api
from dial.cli.common import UsageError, at_least, scene_argument
from dial.instructions.scene_names import SceneNotFoundError


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "tune",
        help="run a script over a grid of tick lengths and find the fastest reliable one",
        description="Run the script K times at each of N tick lengths from A to B, in "
        "parallel worker processes, and print success rate and task time per tick length. "
        "Exit 0 when some tick length succeeded in every trial, 1 when none did (or the "
        "plot could not be written), 2 on a usage error. See docs/tuning.md.",
    )
    p.add_argument("script", metavar="SCRIPT", help="script path or bundled name")
    scene_argument(p)
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
    p.add_argument("--jobs", type=int, metavar="J", help="worker processes (default: all cores)")
    p.add_argument("--plot", metavar="FILE.png", help="plot success rate and task time")
    p.add_argument("--json", action="store_true", help="print the table as JSON, last line")
    p.set_defaults(func=cmd_tune)


def cmd_tune(args: argparse.Namespace) -> int:
    from dial.scene.resolve import scene_option
    from dial.tune import ProcessExecutor, TuneOptions, parse_ticks, tune

    try:
        ticks = parse_ticks(args.ticks)
    except ValueError as e:
        raise UsageError(f"--ticks: {e}") from None
    at_least("--trials", args.trials, 1)
    at_least("--jobs", args.jobs, 1)
    api.check_options(None, 1.0, args.seed, args.perturb)
    try:
        scene = None if args.scene is None else scene_option(args.scene)
    except SceneNotFoundError as e:
        raise UsageError(str(e)) from None
    options = TuneOptions(
        script=args.script,
        scene=scene,
        ticks=ticks,
        trials=args.trials,
        perturb_mm=args.perturb,
        seed=args.seed,
        plot=Path(args.plot) if args.plot else None,
        json=args.json,
    )
    return tune(options, ProcessExecutor(args.jobs))
