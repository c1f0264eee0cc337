"""The session's loop: a terminal with line editing and completion, or a script on stdin.

At a terminal, ``quit`` (and Ctrl-D) with names not written asks whether to write them; a
failed command is reported and the session goes on. When stdin is not a terminal, each
command is echoed with its answer, and the session stops at the first command that fails,
or at the end of the input with names not written: both exit 1, and the names not written are
printed as world-file text, so that nothing saved is lost.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable
from typing import TextIO

from dial.errors import DialError
from dial.instructions.types import FINGERS
from dial.scene.world import JOINTS
from dial.teach.commands import FRAMES, SPECS, parse_command, strip_comment
from dial.teach.session import Reply, Session

PROMPT = "teach> "
KEYWORDS = ("pose", "location", "relative-to", "replace", "axes=world", "fingers=", "for=")

Hook = Callable[[str], None]  # called after each command that ran, with its line


def completions(session: Session) -> list[str]:
    """Every word tab completion offers: commands, the scene's names and keywords."""
    w = session.world
    words = [*SPECS, *w.poses, *w.locations, *w.programs, *w.objects]
    return sorted({*words, *FINGERS, *JOINTS, *FRAMES, *KEYWORDS})


def _one(session: Session, line: str, after: Hook | None) -> Reply | None:
    command = parse_command(line)
    if command is None:
        return None
    reply = session.execute(command, strip_comment(line))
    if after is not None:
        after(strip_comment(line))
    return reply


def scripted(session: Session, lines: Iterable[str], out: TextIO, after: Hook | None) -> int:
    """Run commands from a non-terminal stdin; 0 when all ran and nothing is left unwritten."""
    for raw in lines:
        line = raw.rstrip("\n")
        if not strip_comment(line):
            continue
        print(f"{PROMPT}{line}", file=out)
        try:
            reply = _one(session, line, after)
        except DialError as e:  # a command that could not be done; nothing changed
            print(f"error: {e}", file=out)
            return _lost(session, f"stopped at '{line}'")
        if reply is not None:
            print(reply.text, file=out, flush=True)
            if reply.quit:
                return 0
    if session.unsaved:
        return _lost(session, "end of input")
    return 0


def _lost(session: Session, why: str) -> int:
    print(f"dial: teach: {why}", file=sys.stderr)
    if session.unsaved:
        print(
            f"dial: teach: not written to {session.target.path} (add 'write' to the script); "
            f"the names saved were:\n{session.pending_text()}",
            file=sys.stderr,
        )
    return 1


def interactive(session: Session, after: Hook | None) -> int:
    """Read commands at a terminal, with readline's line editing and tab completion."""
    _readline(session)
    print("type 'help' for the commands, 'quit' to end")
    while True:
        try:
            line = input(PROMPT)
        except KeyboardInterrupt:
            print()
            continue
        except EOFError:
            print()
            line = "quit"
        try:
            if strip_comment(line) == "quit" and session.unsaved and not _confirm_quit(session):
                continue
            # Past the question (or with nothing to lose), quit is quit!.
            reply = _one(session, "quit!" if strip_comment(line) == "quit" else line, after)
        except DialError as e:  # a command that could not be done; nothing changed
            print(f"error: {e}")
            continue
        except KeyboardInterrupt:
            print("\ninterrupted; the robot is back where it was before the command")
            continue
        if reply is not None:
            print(reply.text)
            if reply.quit:
                return 0


def _confirm_quit(session: Session) -> bool:
    """Ask what to do with names not written; True to quit."""
    names = ", ".join(e.name for e in session.unsaved)
    while True:
        try:
            answer = input(f"{names} not written. Write them first? [y]es, [n]o, [c]ancel: ")
        except (EOFError, KeyboardInterrupt):
            print()
            return False
        answer = answer.strip().lower()[:1]
        if answer == "y":
            print(session.write())
            return True
        if answer == "n":
            return True
        if answer == "c":
            return False


def _readline(session: Session) -> None:
    try:
        import readline
    except ImportError:  # no line editing on this platform; input() still works
        return

    def complete(text: str, state: int) -> str | None:
        matches = [w for w in completions(session) if w.startswith(text)]
        return matches[state] if state < len(matches) else None

    readline.set_completer(complete)
    readline.set_completer_delims(" \t")
    readline.parse_and_bind("tab: complete")
