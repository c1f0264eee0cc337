"""What the subcommands share: script loading, ``--scene``, and usage errors."""

from __future__ import annotations

import argparse

from dial.api import load
from dial.errors import OptionError
from dial.parser.script import Script

UsageError = OptionError  # a usage problem: exit status 2


def load_script(arg: str, scene: str | None) -> Script:
    """A script argument (a path, else a bundled name), checked against ``--scene``."""
    return load(arg, scene=scene)


def scene_argument(p: argparse.ArgumentParser, checking: bool = False) -> None:
    what = "check names against" if checking else "run in"
    p.add_argument(
        "--scene",
        metavar="NAME_OR_PATH",
        help=f"{what} this scene instead of the script's @scene (so do the scripts it "
        "@calls): a world file path, else a bundled scene name",
    )


def at_least(flag: str, value: int | None, least: int) -> None:
    if value is not None and value < least:
        raise UsageError(f"{flag} must be at least {least}, got {value}")
