"""``dial teach`` and ``dial world``: the parsers; the work is in :mod:`dial.teach`."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from dial.cli.common import UsageError, plot_usage

_TABLE = "(the command table)"  # dial teach --help's epilog, written when it is printed


class _TeachHelp(argparse.RawDescriptionHelpFormatter):
    """``dial teach --help``: the command table is read from :mod:`dial.teach.commands` only
    when the help is printed, so that building the parser (every command) stays quick."""

    def add_text(self, text: str | None) -> None:
        if text == _TABLE:
            from dial.teach.commands import help_text

            text = (
                help_text() + "\n\nlengths are mm and angles degrees unless a unit is written "
                "(1cm, 0.1rad); 'appro' and 'depart' take metres, as in world-file programs."
            )
        super().add_text(text)


def add_parsers(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "teach",
        help="jog the arm, move and limp the fingers, and save poses and locations",
        description="An interactive session on a scene: jog the tool, drive joints, move "
        "and limp fingers, go to locations, then save the hand's pose and the tool's "
        "location under new names and write them into the world file (comments and layout "
        "kept, a .bak backup). At a terminal, commands have line editing and tab "
        "completion; when stdin is not a terminal they are read line by line and echoed, "
        "and the first command that fails ends the session (exit 1). See docs/teaching.md.",
        epilog=_TABLE,
        formatter_class=_TeachHelp,
    )
    p.add_argument(
        "--scene", required=True, metavar="NAME_OR_PATH", help="a bundled scene or world file"
    )
    p.add_argument(
        "--into",
        metavar="FILE",
        help="write the saved names into FILE (created to extend the scene's world) "
        "instead of the scene's own world file",
    )
    p.add_argument("--snapshot", metavar="DIR", help="write a PNG of the scene after each command")
    p.add_argument("--viewer", action="store_true", help="show the scene live in MuJoCo's viewer")
    p.set_defaults(func=cmd_teach)

    p = sub.add_parser(
        "world",
        help="list a scene's objects, poses, locations, programs and criteria",
        description="Print a scene's world model as aligned text: the objects with their "
        "believed poses, the hand poses, the locations (in the world, and as defined when "
        "relative to an object), the programs and the success criteria. With --picture, "
        "also render the scene with every location drawn as a labelled frame.",
    )
    p.add_argument(
        "scene",
        metavar="SCENE",
        nargs="?",
        help="a bundled scene name (ROBOT/NAME for another robot's) or a world file path",
    )
    p.add_argument("--picture", metavar="FILE.png", help="draw the named frames over the scene")
    p.add_argument(
        "--believed",
        metavar="LOG.jsonl",
        help="instead of a scene: from a run's log, each object's believed pose (and size) "
        "beside its true pose at the end of the run, and every change of the world model",
    )
    p.set_defaults(func=cmd_world)


def _scene(arg: str, option: str = "--scene") -> str:
    from dial.instructions.scene_names import SceneNotFoundError
    from dial.scene.resolve import scene_option

    try:
        return scene_option(arg, option)
    except SceneNotFoundError as e:
        raise UsageError(str(e)) from None


def cmd_teach(args: argparse.Namespace) -> int:
    if args.viewer and args.snapshot:
        raise UsageError("--viewer and --snapshot: choose one (--snapshot is for no display)")
    scene = _scene(args.scene)
    if args.snapshot:
        plot_usage("--snapshot")
    if args.viewer:
        from dial.recording.viewer import require_display

        require_display("--viewer", instead="--snapshot DIR")  # teach has no --record
    from dial.teach.app import teach

    snapshot = Path(args.snapshot) if args.snapshot else None
    return teach(scene, args.into, snapshot=snapshot, viewer=args.viewer)


def cmd_world(args: argparse.Namespace) -> int:
    if args.believed is not None:
        if args.scene is not None or args.picture:
            raise UsageError(
                "--believed LOG reads the scene from the log: give no SCENE or --picture"
            )
        from dial.teach.runlog import believed_from_log

        sys.stdout.write(believed_from_log(Path(args.believed)))
        return 0
    if args.scene is None:
        raise UsageError("give a SCENE (a bundled scene name or a world file), or --believed LOG")
    scene = _scene(args.scene, "SCENE")  # an argument here, not --scene
    if args.picture:
        if Path(args.picture).suffix.lower() != ".png":
            raise UsageError(f"--picture writes a .png file, not '{args.picture}'")
        plot_usage("--picture")
    from dial.teach.app import world

    text, frames = world(scene, Path(args.picture) if args.picture else None)
    sys.stdout.write(text)
    if args.picture:
        print(f"{args.picture}: {frames} location frames drawn", file=sys.stderr)
    return 0
