"""``dial tune``: a sweep of tick lengths, in parallel, for the fastest reliable one."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from dial.cli.common import (
    UsageError,
    at_least,
    dataset_arguments,
    dataset_request,
    load_script,
    scene_argument,
    sigterm_as_interrupt,
)

if TYPE_CHECKING:
    from dial.dataset.plan import Request


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "tune",
        help="run a script over a grid of tick lengths and find the fastest reliable one",
        description="Run the script K times at each of N tick lengths from A to B, in "
        "parallel worker processes or as Ray tasks, and print success rate and task time "
        "per tick length. "
        "Exit 0 when some tick length succeeded in every trial, 1 when none did (or the "
        "plot could not be written), 2 on a usage error, 130 on Ctrl-C and 143 on SIGTERM "
        "(the workers are stopped). See docs/tuning.md.",
    )
    p.add_argument("script", metavar="SCRIPT", help="script path or bundled name")
    scene_argument(p)
    p.add_argument(
        "--ticks",
        metavar="A:B:N",
        help="N tick lengths from A to B s inclusive, linearly spaced (e.g. 0.05:0.5:10); "
        "default: the script's own tick (@tick, else 0.25 s)",
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
        "--disturb",
        action="append",
        default=[],
        metavar="SPEC",
        help="a deliberate fault in every trial, repeatable, as for dial run: 'push body=NAME "
        "force=FX,FY,FZ at=T for=D' or 'sense sensor=KIND:FINGER at=T [for=D]'",
    )
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
    dataset_arguments(p, sweep=True)
    p.set_defaults(func=cmd_tune)


def _own_tick(script: str, scene: str | None) -> tuple[float]:
    """Without ``--ticks``, the script's own tick (checked here, as the sweep would)."""
    from dial.scheduler.types import DEFAULT_TICK

    return (load_script(script, scene).tick or DEFAULT_TICK,)


def cmd_tune(args: argparse.Namespace) -> int:
    from dial import api
    from dial.disturb import parse_disturbance
    from dial.instructions.scene_names import SceneNotFoundError
    from dial.scene.resolve import scene_option
    from dial.tune import ProcessExecutor, TuneOptions, models, parse_ticks, tune

    try:
        ticks = parse_ticks(args.ticks) if args.ticks is not None else ()
    except ValueError as e:
        raise UsageError(f"--ticks: {e}") from None
    at_least("--trials", args.trials, 1)
    at_least("--jobs", args.jobs, 1)
    api.check_options(None, 1.0, args.seed, args.perturb)
    if args.plot is not None:  # a sweep can take hours: say so now, not after it
        if Path(args.plot).suffix.lower() != ".png":
            raise UsageError(f"--plot writes a .png file, not '{args.plot}'")
        api.writable(args.plot, "the plot")
    disturb = tuple(parse_disturbance(spec) for spec in args.disturb)  # before anything runs
    try:
        scene = None if args.scene is None else scene_option(args.scene)
    except SceneNotFoundError as e:
        raise UsageError(str(e)) from None
    dataset, request = _dataset(args)
    options = TuneOptions(
        script=args.script,
        scene=scene,
        ticks=ticks or _own_tick(args.script, scene),
        trials=args.trials,
        perturb_mm=args.perturb,
        seed=args.seed,
        plot=Path(args.plot) if args.plot else None,
        json=args.json,
        disturb=disturb,
        dataset=dataset,
        request=request,
    )
    # Each worker compiles a model file once and gives each trial a copy (dial.tune.models).
    if args.executor == "process":
        if args.address is not None:
            raise UsageError("--address needs --executor ray")
        # spawn: a fork server (preload=models.PRELOAD) measured no faster for one pool
        with sigterm_as_interrupt():  # the workers are stopped, as on Ctrl-C
            return tune(options, ProcessExecutor(args.jobs, initializer=models.install))
    from dial.tune.ray_executor import RayExecutor, RayUsageError

    try:
        executor = RayExecutor(args.address, args.jobs, initializer=models.install)
    except RayUsageError as e:
        raise UsageError(str(e)) from None
    with sigterm_as_interrupt():
        return tune(options, executor)


def _dataset(args: argparse.Namespace) -> tuple[Path | None, Request | None]:
    """``--dataset`` and its options, checked before any trial runs."""
    folder, fps, cameras = dataset_request(args)
    if folder is None:
        return None, None
    from dial.dataset.plan import Request, check_request

    request = Request(50 if fps is None else fps, tuple(cameras), args.successful_only)
    check_request(request)
    return Path(folder), request
