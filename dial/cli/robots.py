"""``dial robots`` and ``dial robots check DIR``: the parsers; the work is in :mod:`dial.robots`."""

from __future__ import annotations

import argparse
import json
import sys


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "robots",
        help="list the bundled robots, or check a robot folder",
        description="List the bundled robots: each one's folder, arm joints and tool site, "
        "fingers and their joints, load and tactile sensors, and scenes. 'dial robots check "
        "DIR' validates a robot folder (its robot.toml against its MJCF) and prints every "
        "problem as robot.toml:LINE:COL: message, with the line and a caret; exit 1 if any. "
        "See docs/robots.md.",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object (a list of robots)")
    p.set_defaults(func=cmd_robots)
    actions = p.add_subparsers(dest="action", metavar="ACTION")
    c = actions.add_parser(
        "check",
        help="validate a robot folder against its MJCF",
        description="Validate a robot folder: robot.toml's syntax and keys, then every name "
        "it gives against the compiled MJCF (joints with limits, position servos on their "
        "joints, sites, tactile and load sensors of the right kind) and its figures against "
        "the model (tendon moment arm, the drives' force limit).",
    )
    c.add_argument("folder", metavar="DIR", help="the robot folder (or its robot.toml)")
    c.set_defaults(func=cmd_check)


def cmd_robots(args: argparse.Namespace) -> int:
    from dial.robots.bundled import bundled_profiles, describe, listing

    profiles = bundled_profiles()
    if args.json:
        print(json.dumps([describe(p) for p in profiles]))
    else:
        sys.stdout.write(listing(profiles))
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    from dial.robots.check import check_robot, require_folder

    folder = require_folder(args.folder)
    problems = check_robot(folder)
    for problem in problems:
        print(problem.render())
    if problems:
        n = len(problems)
        print(f"{folder}: {n} problem{'s' if n != 1 else ''}")
        return 1
    print(f"{folder}: OK")
    return 0
