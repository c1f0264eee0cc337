"""``dial show``: the compiled timeline as an aligned text chart of absolute ticks.

A pure function from a checked script to text.
"""

from __future__ import annotations

from dial.instructions.types import EFFECTORS
from dial.parser.script import Script
from dial.parser.timeline import MAX_ITEMS, MAX_TICKS, Layout, Placed, PlacedWatch, Section, expand


def _ranges(ticks: range) -> str:
    if not ticks:
        return "-"
    return str(ticks.start) if len(ticks) == 1 else f"{ticks.start}-{ticks[-1]}"


def _lane(placed: list[Placed], watched: list[PlacedWatch], length: int) -> str:
    cells = [" "] * length
    for w in watched:
        cells[w.start - 1 : w.end] = "~" * (w.end - w.start + 1)
    for p in placed:
        cells[p.start - 1] = "#"
        for t in range(p.start + 1, p.exec_end + 1):
            cells[t - 1] = "="
        for t in range(p.exec_end + 1, p.hold_end + 1):
            cells[t - 1] = "-"
    return "".join(cells).rstrip()


def _ruler(length: int) -> str:
    cells = [" "] * (length + 4)
    for t in (1, *range(10, length + 1, 10)):
        label = str(t)
        cells[t - 1 : t - 1 + len(label)] = label
    return "".join(cells).rstrip()


def _where(s: Section) -> str:
    """A section's ticks; an ending takes none and happens after tick ``last``."""
    return f"{s.first}-{s.last}" if s.first <= s.last else f"after {s.last}"


def _compact_note(layout: Layout) -> str:
    """What a compact layout leaves out."""
    note = (
        f"(shown compactly: expanded, the timeline exceeds {MAX_TICKS} ticks or "
        f"{MAX_ITEMS} runs and sections, so each counted @repeat is drawn once and the ticks "
        "below are not absolute"
    )
    if layout.cut:
        note += f"; the chart stops after tick {layout.length}"
    return note + ")"


def render(script: Script, layout: Layout | None = None) -> str:
    """The chart (one lane per event), the sections, and every run with its ticks."""
    layout = layout or expand(script)
    names = list(layout.lanes)
    width = max([len(n) for n in names] + [len("tick")]) + 2
    tick = f"tick {script.tick:g} s" if script.tick is not None else "default tick"
    own = script.program.scene.text if script.program.scene else None
    scene = script.scene_override or own or "none"
    out = [f"{script.path}: scene {scene}, {tick}, {layout.expanded or layout.length} ticks"]
    if layout.compact:
        out.append(_compact_note(layout))
    out += ["", "tick".ljust(width) + _ruler(layout.length)]
    runs: dict[str, list[Placed]] = {name: [] for name in names}
    watched: dict[str, list[PlacedWatch]] = {name: [] for name in names}
    for p in layout.runs:
        runs[p.run.event].append(p)
    for w in layout.watches:
        watched[w.watch.event].append(w)
    for name in names:
        out.append(name.ljust(width) + _lane(runs[name], watched[name], layout.length))
    out += ["", "sections (#N: the block's number for --save-at block:N; #?: up to the run):"]
    span_w = max([len(_where(s)) for s in layout.sections] + [5])
    for s in layout.sections:
        number = "" if s.first > s.last else f"#{s.block}" if s.block is not None else "#?"
        out.append(f"  {_where(s):<{span_w}}  {number:>5}  {s.label}  ({s.path}:{s.line})")
    out += ["", "runs:"]
    ev_w = max([len(n) for n in names] + [5])
    for p in layout.runs:
        ex = range(p.start, p.exec_end + 1)
        held = range(p.exec_end + 1, p.hold_end + 1)
        effectors = " ".join(e for e in EFFECTORS if e in p.run.effectors) or "(sensing)"
        out.append(
            f"  {p.run.event:<{ev_w}}  {_ranges(range(p.start, p.hold_end + 1)):>7}"
            f"  exec {_ranges(ex):<7}  held {_ranges(held):<7}  {effectors}"
        )
    if layout.watches:
        out += ["", "watched (sensed every control period):"]
        for w in layout.watches:
            where = f"{w.path}:{w.watch.line}"
            ticks = _ranges(range(w.start, w.end + 1))
            out.append(f"  {w.watch.event:<{ev_w}}  {ticks:>7}  ({where})")
    return "\n".join(out) + "\n"
