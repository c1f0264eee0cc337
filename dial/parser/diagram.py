"""Read the diagram of an execution line: runs (``#``, ``=``, ``-``) or watched spans (``~``)."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from dial.errors import Span

# One token: a run (its '#', then every '=', then every '-'), a watched span, idle ticks, or
# any other single character (an error).
_TOKEN = re.compile(r"(#=*-*)|(~+)|([ .]+)|(.)")


@dataclass
class Diagram:
    """The marks of one execution line, as 0-based columns (inclusive)."""

    runs: list[tuple[int, int, int]] = field(default_factory=list)  # start, exec_end, hold_end
    watches: list[tuple[int, int]] = field(default_factory=list)  # start, end


def _mixed(number: int, col: int, ch: str) -> tuple[Span, str]:
    what = "a watched line" if ch in "#=-" else "a line with runs ('#', '=', '-')"
    return (
        Span.at(number, col + 1),
        f"'{ch}' on {what}: a watched line holds only '~' (and '.' or spaces); "
        "draw the watch and the runs on separate lines",
    )


def _stray(number: int, col: int, ch: str, event: str, after_run: bool) -> tuple[Span, str]:
    span = Span.at(number, col + 1)
    if ch == "=" and after_run:
        return span, "'=' after '-': within a run every '=' comes before any '-'"
    if ch in "=-":
        role = "continues" if ch == "=" else "holds"
        return span, f"misplaced '{ch}': it {role} a run, so it must follow that run's '#'"
    if ch == "\t":
        return span, "tab inside the diagram: its column is ambiguous; use spaces"
    return (
        span,
        f"unexpected '{ch}' in the diagram of '{event}'; "
        "expected '#', '=', '-', '~', '.' or a space",
    )


def read_diagram(number: int, code: str, start: int, event: str) -> Diagram | tuple[Span, str]:
    """The marks of ``code[start:]``, or the first problem on the line (span, message).

    Only the first problem is reported: the rest of a line usually follows from it.
    """
    out = Diagram()
    last_run_end = -2
    for m in _TOKEN.finditer(code, start):
        col = m.start()
        if m.group(1):
            if out.watches:
                return _mixed(number, col, "#")
            text = m.group(1)
            exec_len = len(text) - len(text.lstrip("#="))
            out.runs.append((col, col + exec_len - 1, m.end() - 1))
            last_run_end = m.end()
        elif m.group(2):
            if out.runs:
                return _mixed(number, col, "~")
            out.watches.append((col, m.end() - 1))
        elif m.group(4):
            ch = m.group(4)
            if out.watches and ch in "=-":
                return _mixed(number, col, ch)
            return _stray(number, col, ch, event, col == last_run_end)
    return out
