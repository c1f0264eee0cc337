"""The processes: ``dial serve``, ``dial link``, and ``dial run --remote``'s run."""

from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path
from typing import TextIO

import trio

from dial.errors import DialError
from dial.parser.script import Script
from dial.remote.link import Link, LinkSpec, parse_link, serve_link
from dial.remote.operator import RemoteResult, operate
from dial.remote.options import OperatorOptions, Progress
from dial.remote.server import Server
from dial.remote.telemetry import RobotConfig
from dial.remote.tokens import default_token_file, ensure_token, read_token
from dial.scheduler.signals import StopRequest


def serve(args: argparse.Namespace, host: str, port: int, scene: str | None) -> int:
    """``dial serve``: until Ctrl-C or SIGTERM (exit 130 / 143, the robot held)."""
    token_file = Path(args.token_file) if args.token_file else default_token_file(args.log)
    token, created = ensure_token(token_file)
    log: TextIO | None = None
    if args.log is not None:
        try:
            log = open(args.log, "w", encoding="utf-8")  # noqa: SIM115
        except OSError as e:
            raise DialError(f"cannot write the log: {e.strerror or e}: '{args.log}'") from None
    config = RobotConfig(
        scene, args.perturb, args.seed, tuple(args.disturb), args.pace, args.watchdog
    )
    server = Server(config, token, log)

    async def main() -> None:
        async with trio.open_nursery() as nursery:
            bound = await nursery.start(server.serve, host, port)
            where = f"[{host}]" if ":" in host else host
            made = "new token written to" if created else "token file"
            print(
                f"dial serve: listening on ws://{where}:{bound} ({made} {token_file})", flush=True
            )
            with trio.open_signal_receiver(2, 15) as signals:  # SIGINT, SIGTERM
                async for signum in signals:
                    status[0] = 130 if signum == 2 else 143
                    nursery.cancel_scope.cancel()
                    return

    status = [0]
    try:
        trio.run(main)
    finally:
        server.shutdown()
        if log is not None:
            with contextlib.suppress(OSError):
                log.close()
    print("dial serve: stopped; the robot holds", file=sys.stderr)
    return status[0]


def run_link(host: str, port: int, target: str, spec: LinkSpec) -> int:
    """``dial link``: until Ctrl-C or SIGTERM."""
    link = Link(spec, target)

    async def main() -> None:
        async with trio.open_nursery() as nursery:
            bound = await nursery.start(serve_link, link, host, port)
            print(f"dial link: ws://{host}:{bound} -> {target} ({spec.text()})", flush=True)
            with trio.open_signal_receiver(2, 15) as signals:
                async for _ in signals:
                    nursery.cancel_scope.cancel()
                    return

    trio.run(main)
    up, down = link.up, link.down
    print(
        f"dial link: {up.messages} messages ({up.bytes} bytes) up, "
        f"{down.messages} ({down.bytes} bytes) down",
        file=sys.stderr,
    )
    return 0


def run_remote(
    args: argparse.Namespace,
    script: Script,
    tick: float,
    log: TextIO | None,
    stop: StopRequest,
    progress: Progress | None,
) -> RemoteResult:
    """``dial run --remote``: the operator's run."""
    options = OperatorOptions(
        url=args.remote,
        token=read_token(Path(args.token_file) if args.token_file else default_token_file()),
        split=args.split,
        link=None if args.link is None else parse_link(args.link),
        lead=args.lead,
        diverge_mm=args.diverge,
        tick=tick,
        log=log,
        progress=progress,
        predict=not args.no_predict,
        record=None if args.record is None else Path(args.record),
        rerun=args.rerun,
        quiet=args.quiet,
    )
    return trio.run(operate, script, options, stop)
