"""``dial preview``: the parser; the work is in :mod:`dial.preview`."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from dial.cli.common import UsageError, load_script, plot_usage, scene_argument


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "preview",
        help="a kinematic dry run: reach, joint limits and collisions, without physics",
        description="A kinematic dry run of a script, without contact dynamics: every arm "
        "target is solved and every hand pose set, in order, from the world's home; "
        "reachability, joint limits (arm and hand), and collisions of the robot with the "
        "fixed world, the objects and itself are checked. A guarded move goes until the "
        "hand first touches something (or its full max travel), a grasp closes until each "
        "finger touches, and what it grasps is carried. Both branches of every @if and every "
        "@on reaction are previewed; a loop's body once. Every problem is printed as "
        "FILE:LINE:COL: EVENT: message at the run that causes it; exit 1 if any. Problems "
        "on paths the preview does not take (the other branch of an @if, a reaction that "
        "does not fire) are notes, which --notes prints. See docs/debugging.md.",
    )
    p.add_argument("script", metavar="SCRIPT", help="script path or bundled name")
    scene_argument(p)
    p.add_argument(
        "--storyboard",
        metavar="FILE.png",
        help="draw one panel per block previewed, the robot at the block's end",
    )
    p.add_argument(
        "--notes", action="store_true", help="also print the notes (problems on paths not taken)"
    )
    p.set_defaults(func=cmd_preview)


def cmd_preview(args: argparse.Namespace) -> int:
    storyboard = None
    if args.storyboard:
        if Path(args.storyboard).suffix.lower() != ".png":
            raise UsageError(f"--storyboard writes a .png file, not '{args.storyboard}'")
        plot_usage("--storyboard")
        from dial.api import writable

        storyboard = writable(args.storyboard, "the storyboard")
    script = load_script(args.script, args.scene)
    from dial.preview import preview

    result = preview(script, storyboard)
    for line in result.problems + (result.notes if args.notes else []):
        print(line)
    print(result.summary())
    if storyboard is not None:
        print(f"{storyboard}: {result.panels} panels", file=sys.stderr)
    return 0 if result.ok else 1
