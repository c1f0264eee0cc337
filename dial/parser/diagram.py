"""Read the diagram of an execution line: runs (``#``, ``=``, ``-``) or watched spans (``~``)."""

from __future__ import annotations

import re
from typing import NamedTuple

# One token: a run (its '#', then every '=', then every '-'), a watched span, idle ticks, or
# any other single character (an error).
_TOKEN = re.compile(r"(#=*-*)|(~+)|([ .]+)|(.)")
# Diagrams without a problem, read without a Python loop over their tokens.
# Possessive quantifiers: a diagram that does not match fails at once, never backtracking.
_RUNS = re.compile(r"(?:#=*+-*+|[ .])*+")
_WATCHES = re.compile(r"[~ .]*+")
_RUN = re.compile(r"#(=*)(-*)")
_WATCH = re.compile(r"~+")


class Diagram(NamedTuple):
    """The marks of one execution line, as 0-based columns (inclusive)."""

    runs: tuple[tuple[int, int, int], ...]  # start, exec_end, hold_end
    watches: tuple[tuple[int, int], ...]  # start, end


def _mixed(col: int, ch: str) -> tuple[int, str]:
    what = "a watched line" if ch in "#=-" else "a line with runs ('#', '=', '-')"
    return (
        col,
        f"'{ch}' on {what}: a watched line holds only '~' (and '.' or spaces); "
        "draw the watch and the runs on separate lines",
    )


def _stray(col: int, ch: str, event: str, after_run: bool) -> tuple[int, str]:
    if ch == "=" and after_run:
        return col, "'=' after '-': within a run every '=' comes before any '-'"
    if ch in "=-":
        role = "continues" if ch == "=" else "holds"
        return col, f"misplaced '{ch}': it {role} a run, so it must follow that run's '#'"
    if ch == "\t":
        return col, "tab inside the diagram: its column is ambiguous; use spaces"
    return (
        col,
        f"unexpected '{ch}' in the diagram of '{event}'; "
        "expected '#', '=', '-', '~', '.' or a space",
    )


def read_diagram(code: str, start: int, event: str) -> Diagram | tuple[int, str]:
    """The marks of ``code[start:]``, or the first problem on the line (0-based column of
    the offending character, message).

    Only the first problem is reported: the rest of a line usually follows from it.
    """
    if _RUNS.fullmatch(code, start):
        runs = [(m.start(), m.end(1) - 1, m.end() - 1) for m in _RUN.finditer(code, start)]
        return Diagram(tuple(runs), ())
    if _WATCHES.fullmatch(code, start):
        watches = [(m.start(), m.end() - 1) for m in _WATCH.finditer(code, start)]
        return Diagram((), tuple(watches))
    return _first_problem(code, start, event)


def _first_problem(code: str, start: int, event: str) -> Diagram | tuple[int, str]:
    """Read the diagram token by token, to find where it goes wrong."""
    runs: list[tuple[int, int, int]] = []
    watches: list[tuple[int, int]] = []
    last_run_end = -2
    for m in _TOKEN.finditer(code, start):
        col = m.start()
        if m.group(1):
            if watches:
                return _mixed(col, "#")
            text = m.group(1)
            exec_len = len(text) - len(text.lstrip("#="))
            runs.append((col, col + exec_len - 1, m.end() - 1))
            last_run_end = m.end()
        elif m.group(2):
            if runs:
                return _mixed(col, "~")
            watches.append((col, m.end() - 1))
        elif m.group(4):
            ch = m.group(4)
            if watches and ch in "=-":
                return _mixed(col, ch)
            return _stray(col, ch, event, col == last_run_end)
    return Diagram(tuple(runs), tuple(watches))
