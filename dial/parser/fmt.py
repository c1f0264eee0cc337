"""``dial fmt``: re-align diagrams, definition columns and tick rulers.

Formatting only moves whitespace and normalises spacing inside parameters, so the
result parses to the same program. Lines that a comment crosses into, out of or
through are left exactly as written (and so is the block they belong to).
"""

from __future__ import annotations

import re

from dial.errors import ScriptError
from dial.parser.parse import NAME, parse_partial
from dial.parser.source import Kind, Line, scan
from dial.parser.words import WordError, tokenize

# A tick ruler comment ("//  1234567890"): opener, padding, digits, closer. No two parts can
# take the same characters, so a long line that is no ruler fails in linear time.
_RULER = re.compile(r"^(\s*+(?://|/\*))( *+)([0-9](?:[0-9 ]*[0-9])?)( *+(?:\*/)?\s*+)$")


def _tail(ln: Line) -> str:
    """A trailing comment, with two spaces before it."""
    return "  " + ln.text[ln.comment_at :].rstrip() if ln.comment_at is not None else ""


def _diagram_col(ln: Line) -> int:
    m = NAME.match(ln.code)
    assert m is not None
    j = m.end()
    while ln.code[j].isspace():
        j += 1
    return j


def _definitions(lines: list[Line], out: list[str]) -> None:
    group: list[tuple[Line, str, str, str]] = []

    def flush() -> None:
        if not group:
            return
        w1 = max(len(e) for _, e, _, _ in group)
        w2 = max(len(i) for _, _, i, _ in group)
        for ln, event, instr, params in group:
            out[ln.number - 1] = (f"% {event:<{w1}} {instr:<{w2}} {params}".rstrip()) + _tail(ln)
        group.clear()

    for ln in lines:
        if ln.kind is not Kind.DEFINITION or ln.foreign:
            flush()
            continue
        fields = ln.code[1:].split(None, 2)
        start = ln.code.index(fields[1], ln.code.index(fields[0]) + len(fields[0]))
        params = tokenize(ln.number, ln.code, start + len(fields[1]))
        group.append((ln, fields[0], fields[1], " ".join(p.render() for p in params)))
    flush()


def _directive(ln: Line) -> str:
    m = NAME.match(ln.code, 1)
    assert m is not None
    params = tokenize(ln.number, ln.code, m.end())
    return " ".join(["@" + m.group(), *(p.render() for p in params)]) + _tail(ln)


def _shift_ruler(text: str, shift: int) -> str:
    m = _RULER.match(text)
    if m is None or shift == 0:
        return text
    opener, pad, digits, closer = m.groups()
    if len(pad) + shift < 0:
        return text
    return (opener + " " * (len(pad) + shift) + digits + closer).rstrip()


def format_text(text: str, path: str = "<script>") -> str:
    """Return ``text`` formatted; raise :class:`ScriptError` if it does not parse."""
    _, diags = parse_partial(text, path)
    if diags:
        raise ScriptError(diags)
    lines, _ = scan(text)
    out = [ln.text.rstrip() for ln in lines]
    try:
        _definitions(lines, out)
        for ln in lines:
            if ln.kind is Kind.DIRECTIVE and not ln.foreign:
                out[ln.number - 1] = _directive(ln)
    except WordError as e:  # parse_partial accepted it, so this is a bug, not bad input
        raise AssertionError(f"fmt could not re-read line {e.span.line}: {e.message}") from e

    execs = [ln for ln in lines if ln.kind is Kind.EXECUTION]
    if execs:
        target = max(NAME.match(ln.code).end() for ln in execs) + 1  # type: ignore[union-attr]
        block: list[Line] = []
        rulers: list[Line] = []
        ends: list[Line | None] = [*lines, None]
        for item in ends:
            if item is not None and item.kind is Kind.COMMENT:
                if _RULER.match(item.text) and not item.foreign:
                    rulers.append(item)
                continue
            if item is not None and item.kind is Kind.EXECUTION:
                block.append(item)
                continue
            if block:
                _align(block, rulers, target, out)
            block, rulers = [], []
    return "\n".join(out).rstrip("\n") + "\n"


def _align(block: list[Line], rulers: list[Line], target: int, out: list[str]) -> None:
    if any(ln.foreign for ln in block):
        return
    cols = {ln.number: _diagram_col(ln) for ln in block}
    base = min(cols.values())
    for ln in block:
        name = NAME.match(ln.code).group()  # type: ignore[union-attr]
        col = cols[ln.number]
        out[ln.number - 1] = (name.ljust(target) + " " * (col - base) + ln.text[col:]).rstrip()
    for r in rulers:
        out[r.number - 1] = _shift_ruler(out[r.number - 1], target - base)
