"""``dial serve``, ``dial link``, and ``dial run --remote``'s options (docs/remote.md).

trio-websocket and the remote modules load only in these commands: ``import dial``,
``dial check`` and ``--help`` stay light.
"""

from __future__ import annotations

import argparse
import ipaddress
import math
import sys

from dial.cli.common import UsageError, scene_argument

LOOPBACK = "127.0.0.1"


def listen_address(text: str, flag: str = "--listen") -> tuple[str, int]:
    """``HOST:PORT`` (port 0: a free one) as (host, port); a usage error otherwise."""
    host, colon, port = text.rpartition(":")
    host = host.strip("[]")
    if not colon or not host or not port.isdigit() or int(port) > 65535:
        raise UsageError(f"{flag}: expected HOST:PORT, got '{text}'")
    return host, int(port)


def add_parsers(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    add_parser(sub)
    _link_parser(sub)


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """``dial serve``."""
    p = sub.add_parser(
        "serve",
        help="be the robot: run what a remote operator sends (docs/remote.md)",
        description="Serve the simulated robot to one remote operator at a time over "
        "WebSocket (JSON, protocol version 1, docs/remote.md). The robot holds its true "
        "world (--perturb, --seed, --disturb happen here), runs paced to the wall clock "
        "times --pace, and holds every effector when its operator is silent for --watchdog "
        "seconds. It prints its URL and token file. Ctrl-C stops it (the robot holds).",
    )
    scene_argument(p)
    p.add_argument(
        "--listen",
        default=f"{LOOPBACK}:8765",
        metavar="HOST:PORT",
        help="where to listen (default 127.0.0.1:8765, loopback only; port 0: a free one). "
        "Another address must be given here explicitly",
    )
    p.add_argument(
        "--token-file",
        metavar="F",
        help="read the token from F, or write a new one there (mode 0600) when F does not "
        "exist (default: beside --log, else $XDG_STATE_HOME/dial/token)",
    )
    p.add_argument(
        "--watchdog",
        type=float,
        default=1.0,
        metavar="S",
        help="hold every effector when no message came from the operator for S s (default 1)",
    )
    p.add_argument(
        "--pace",
        type=float,
        default=1.0,
        metavar="F",
        help="wall s per simulated s (default 1, real time; 0.2 runs 5 times faster)",
    )
    p.add_argument("--seed", type=int, default=0, metavar="N", help="seed for --perturb")
    p.add_argument(
        "--perturb",
        type=float,
        default=0.0,
        metavar="MM",
        help="displace the true object poses by MM from the believed ones",
    )
    p.add_argument(
        "--disturb",
        action="append",
        default=[],
        metavar="SPEC",
        help="a deliberate fault at the robot, repeatable (as dial run --disturb)",
    )
    p.add_argument(
        "--log",
        metavar="F.jsonl",
        help="the robot's log: every session's records, link records among them",
    )
    p.set_defaults(func=cmd_serve)


def _link_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    q = sub.add_parser(
        "link",
        help="an emulated link between a client and a server (delay, cuts...)",
        description="A WebSocket proxy that delays, jitters, throttles, cuts or blackholes "
        "what passes between any client and a dial server. SPEC: 'delay=2s jitter=300ms "
        "bandwidth=2400bps cut=T:D blackhole=T seed=N' (times from the first connection).",
    )
    q.add_argument("--listen", required=True, metavar="HOST:PORT", help="where clients connect")
    q.add_argument("--to", required=True, metavar="URL", help="the server, ws://HOST:PORT")
    q.add_argument("spec", metavar="SPEC", help="what the link does, e.g. 'delay=1s'")
    q.set_defaults(func=cmd_link)


def add_run_options(p: argparse.ArgumentParser) -> None:
    """``dial run``'s remote options."""
    g = p.add_argument_group(
        "remote robot (docs/remote.md)",
        "Run at a robot served by 'dial serve': the summary and criteria are the robot's, "
        "the log adds link records (sent, acknowledged, reported, late, lost, diverged). "
        "The robot's world (--perturb, --seed, --disturb) is set at 'dial serve'; with "
        "--remote those, the debugging options, --realtime, --video, --viewer, "
        "--log-states, --dataset and --save-world are usage errors.",
    )
    g.add_argument("--remote", metavar="URL", help="the robot's server, ws://HOST:PORT")
    g.add_argument(
        "--token-file",
        metavar="F",
        help="the robot's token file, as 'dial serve' wrote it (default: "
        "$XDG_STATE_HOME/dial/token, that is ~/.local/state/dial/token)",
    )
    g.add_argument(
        "--split",
        choices=("script", "block"),
        default="script",
        help="script: send the checked script whole (default); block: walk the timeline "
        "here and send each block tagged with its start tick",
    )
    g.add_argument(
        "--link",
        metavar="SPEC",
        help="emulate a link on the way: 'delay=2s jitter=300ms bandwidth=2400bps cut=T:D "
        "blackhole=T seed=N' (any of them; as 'dial link')",
    )
    g.add_argument(
        "--lead",
        type=float,
        metavar="S",
        help="--split block: tag a block that waited for a report S s of robot time ahead "
        "(default: 1.5 round trips and 0.2 s; the round trip is --link's worst, else the one "
        "measured at connect, and then the lead is rounded up to 0.5, 1, 2, 4... s; the "
        "operator says which)",
    )
    g.add_argument(
        "--diverge",
        type=float,
        default=10.0,
        metavar="MM",
        help="write a 'diverged' record when the reported tool is more than MM from the "
        "prediction (default 10)",
    )
    g.add_argument(
        "--no-predict",
        action="store_true",
        help="do not predict the robot on this side (no 'diverged' records; --record and "
        "--rerun draw the prediction, so they need it)",
    )


def cmd_serve(args: argparse.Namespace) -> int:
    host, port = listen_address(args.listen)
    if not (math.isfinite(args.watchdog) and args.watchdog > 0):
        raise UsageError(f"--watchdog must be above 0 s, got {args.watchdog:g}")
    if not (math.isfinite(args.pace) and args.pace > 0):
        raise UsageError(f"--pace must be above 0, got {args.pace:g}")
    from dial.api import check_options
    from dial.disturb import parse_disturbance
    from dial.errors import DialError
    from dial.scene.resolve import scene_option

    check_options(None, 1.0, args.seed, args.perturb)
    try:
        for d in args.disturb:
            parse_disturbance(d)
    except DialError as e:
        raise UsageError(str(e)) from None
    scene = None if args.scene is None else scene_option(args.scene)
    if not is_loopback(host):
        print(
            f"dial serve: listening beyond loopback on {host}: whoever reaches it with the "
            "token runs the robot",
            file=sys.stderr,
        )
    from dial.remote.serve import serve

    return serve(args, host, port, scene)


def cmd_link(args: argparse.Namespace) -> int:
    host, port = listen_address(args.listen)
    if not args.to.startswith(("ws://", "wss://")):
        raise UsageError(f"--to: expected ws://HOST:PORT, got '{args.to}'")
    from dial.remote.link import parse_link
    from dial.remote.serve import run_link

    return run_link(host, port, args.to, parse_link(args.spec))


# ``dial run`` options a remote run does not take: (dest, flag, why).
WORLD = "the robot's world is perturbed and disturbed at 'dial serve'"
PACED = "a remote run is paced by the robot: it does not pause, save or resume"
SEEN = "the operator sees the robot in decimated telemetry: frames are a local run's"
MODEL = "the world model that touch updates is the robot's"
LOCAL_ONLY = (
    ("perturb", "--perturb", WORLD),
    ("seed", "--seed", WORLD),
    ("disturb", "--disturb", WORLD),
    ("breaks", "--break", PACED),
    ("step", "--step", PACED),
    ("save_at", "--save-at", PACED),
    ("resume", "--resume", PACED),
    ("realtime", "--realtime", PACED),
    ("video", "--video", SEEN),
    ("viewer", "--viewer", SEEN),
    ("log_states", "--log-states", SEEN),
    ("dataset", "--dataset", SEEN),
    ("save_world", "--save-world", MODEL),
)


def check_remote(args: argparse.Namespace) -> None:
    """Usage errors of ``dial run --remote`` (what only the robot, or only a local run, has)."""
    if args.remote is None:
        for flag in ("token_file", "link", "lead"):
            if getattr(args, flag) is not None:
                raise UsageError(f"--{flag.replace('_', '-')} needs --remote URL")
        if args.split != "script" or args.no_predict:
            raise UsageError("--split and --no-predict need --remote URL")
        return
    if not args.remote.startswith(("ws://", "wss://")):
        raise UsageError(f"--remote: expected ws://HOST:PORT, got '{args.remote}'")
    given = [flag for dest, flag, _ in LOCAL_ONLY if getattr(args, dest)]
    if given:
        why = dict.fromkeys(why for dest, _, why in LOCAL_ONLY if getattr(args, dest))
        raise UsageError(f"{', '.join(given)}: not with --remote ({'; '.join(why)})")
    if (args.record or args.rerun) and args.no_predict:
        raise UsageError(
            "--record and --rerun draw the prediction beside the robot: not with --no-predict"
        )
    if args.record or args.rerun:
        from dial.api import check_watching

        check_watching(args.record, None, args.rerun, False)
    if args.link is not None:
        from dial.remote.link import parse_link  # a usage error before anything connects

        parse_link(args.link)
    if args.lead is not None and args.split != "block":
        raise UsageError("--lead: only with --split block (how far ahead a block is tagged)")
    if args.lead is not None and not (math.isfinite(args.lead) and args.lead > 0):
        raise UsageError(f"--lead must be above 0 s, got {args.lead:g}")
    if not (math.isfinite(args.diverge) and args.diverge > 0):
        raise UsageError(f"--diverge must be above 0 mm, got {args.diverge:g}")


def is_loopback(host: str) -> bool:
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return host == "localhost"
