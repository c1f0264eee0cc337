"""Debugging a run (DESIGN 6.1): breakpoints, stepping, the paused state, save at a block."""

from dial.debug.breaks import Break, parse_break
from dial.debug.console import Console, LineConsole, ScriptedConsole, TerminalConsole
from dial.debug.session import Session

__all__ = [
    "Break",
    "Console",
    "LineConsole",
    "ScriptedConsole",
    "Session",
    "TerminalConsole",
    "parse_break",
]
