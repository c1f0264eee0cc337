"""The timeline laid out for display: every run and watched span placed on absolute ticks.

:func:`expand` lays a whole checked script out, expanding counted repeats and calls.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import NamedTuple

from dial.parser.script import (
    Run,
    Script,
    Step,
    TAbort,
    TBlock,
    TCall,
    TIf,
    TRepeat,
    TResume,
    TRetry,
    Watch,
    iter_steps,
)


@dataclass(frozen=True)
class Section:
    """A stretch of absolute ticks and what it comes from, for display."""

    first: int
    last: int
    label: str
    path: str
    line: int
    # A block's number as the run counts blocks (``--save-at block:N``), where the order is
    # fixed: up to the first @if, loop with a condition, or reaction; else None.
    block: int | None = None


@dataclass(frozen=True)
class Placed:
    """A run placed on absolute ticks."""

    run: Run
    offset: int  # absolute tick of the block's tick 1, minus one
    path: str

    @property
    def start(self) -> int:
        return self.offset + self.run.start

    @property
    def exec_end(self) -> int:
        return self.offset + self.run.exec_end

    @property
    def hold_end(self) -> int:
        return self.offset + self.run.hold_end


@dataclass(frozen=True)
class PlacedWatch:
    """A watched span placed on absolute ticks."""

    watch: Watch
    offset: int  # absolute tick of the block's tick 1, minus one
    path: str

    @property
    def start(self) -> int:
        return self.offset + self.watch.start

    @property
    def end(self) -> int:
        return self.offset + self.watch.end


@dataclass(frozen=True)
class Layout:
    runs: tuple[Placed, ...]
    sections: tuple[Section, ...]
    length: int  # ticks laid out
    watches: tuple[PlacedWatch, ...] = ()
    lanes: tuple[str, ...] = ()  # every event with a run or a watch, in the order met
    # Laid out compactly (too large to expand): each counted repeat drawn once, so ticks after
    # one are not absolute; ``cut`` if the layout also stops early. ``expanded`` is the
    # length of the whole expanded timeline, which :func:`length` gives without laying out.
    compact: bool = False
    cut: bool = False
    expanded: int = 0


def ending_text(step: TResume | TRetry | TAbort) -> str:
    """An ending as written: ``@resume``, ``@retry max N``, ``@abort "MESSAGE"``."""
    if isinstance(step, TResume):
        return "@resume"
    if isinstance(step, TRetry):
        return f"@retry max {step.max}"
    return f'@abort "{step.message}"'


# A timeline that expands to more ticks or items (runs, watches, sections) than this is laid
# out compactly, and a compact layout stops once it reaches them: what a chart can show.
MAX_TICKS = 5_000
MAX_ITEMS = 20_000


class Size(NamedTuple):
    """What an expanded timeline holds: its ticks, and its runs, watches and sections."""

    ticks: int
    items: int


class _Measure:
    """The size of the expanded timeline, by arithmetic: nothing is unrolled, and a script
    called many times is measured once."""

    def __init__(self) -> None:
        self.calls: dict[int, Size] = {}

    def steps(self, steps: tuple[Step, ...]) -> Size:
        ticks = items = 0
        for step in steps:
            size = self.step(step)
            ticks, items = ticks + size.ticks, items + size.items
        return Size(ticks, items)

    def step(self, step: Step) -> Size:
        if isinstance(step, TBlock):
            after = [self.steps(r.body) for r in step.reactions]
            ticks = step.length + max([a.ticks for a in after], default=0)
            extra = sum(a.items or 1 for a in after)  # an empty reaction is one section
            return Size(ticks, len(step.runs) + len(step.watches) + 1 + extra)
        if isinstance(step, TRepeat):
            body = self.steps(step.body)
            n = step.count if step.kind == "count" else 1
            return Size(body.ticks * n, body.items * n)
        if isinstance(step, TIf):
            then, orelse = self.steps(step.then), self.steps(step.orelse)
            return Size(max(then.ticks, orelse.ticks), then.items + orelse.items)
        if isinstance(step, TCall):
            key = id(step.script)
            if key not in self.calls:
                self.calls[key] = self.steps(step.script.timeline)
            return self.calls[key]
        return Size(0, 1)  # an ending: a section of no ticks


def measure(script: Script) -> Size:
    """The size of ``script``'s expanded timeline, in time linear in the script's size."""
    return _Measure().steps(script.timeline)


def length(script: Script) -> int:
    """The number of ticks :func:`expand` lays ``script`` out on, fully expanded."""
    return measure(script).ticks


class _Walk:
    """Places every step of a timeline, in order, on absolute ticks."""

    def __init__(self, compact: bool) -> None:
        self.runs: list[Placed] = []
        self.watches: list[PlacedWatch] = []
        self.sections: list[Section] = []
        self.lanes: dict[str, None] = {}
        self.compact = compact
        self.cut = False
        self.number: int | None = 0  # blocks so far, while their order is fixed

    def full(self, offset: int) -> bool:
        """Whether a compact layout has reached its limits (then it stops)."""
        items = len(self.runs) + len(self.watches) + len(self.sections)
        self.cut = self.cut or (self.compact and (offset >= MAX_TICKS or items >= MAX_ITEMS))
        return self.cut

    def steps(self, steps: tuple[Step, ...], offset: int, path: str, label: str) -> int:
        """Place ``steps`` from ``offset``; return the offset after them."""
        prefix = f"{label} " if label else ""
        for step in steps:
            if self.full(offset):
                break
            if isinstance(step, TBlock):
                offset = self.block(step, offset, path, label, prefix)
            elif isinstance(step, TRepeat):
                if step.kind != "count" or self.compact:
                    self.number = None  # how often it runs is up to the run
                if step.kind == "count" and self.compact:
                    tag = f"{prefix}@repeat {step.count} (drawn once of {step.count})"
                    offset = self.steps(step.body, offset, path, tag)
                elif step.kind == "count":
                    for i in range(step.count):
                        tag = f"{prefix}@repeat {step.count} ({i + 1}/{step.count})"
                        offset = self.steps(step.body, offset, path, tag)
                else:
                    tag = f"{prefix}@repeat {step.kind} {step.condition} (loop, max {step.count})"
                    offset = self.steps(step.body, offset, path, tag)
            elif isinstance(step, TIf):
                self.number = None  # which branch runs is up to the run
                then_end = self.steps(step.then, offset, path, f"{prefix}@if {step.condition}")
                orelse = f"{prefix}@else ({step.condition})"
                offset = max(then_end, self.steps(step.orelse, offset, path, orelse))
            elif isinstance(step, TCall):
                tag = f"{prefix}@call {step.target}"
                offset = self.steps(step.script.timeline, offset, step.script.path, tag)
            else:  # an ending takes no ticks: a zero-length section marks it
                self.sections.append(
                    Section(offset + 1, offset, prefix + ending_text(step), path, step.line)
                )
        return offset

    def block(self, step: TBlock, offset: int, path: str, label: str, prefix: str) -> int:
        """A block, then each of its reactions as a path that starts where the block ends."""
        self.runs.extend(Placed(r, offset, path) for r in step.runs)
        self.watches.extend(PlacedWatch(w, offset, path) for w in step.watches)
        self.lanes.update(dict.fromkeys(r.event for r in step.runs))
        self.lanes.update(dict.fromkeys(w.event for w in step.watches))
        end = offset + step.length
        if self.number is not None:
            self.number += 1
        section = Section(offset + 1, end, label or "block", path, step.line, self.number)
        self.sections.append(section)
        if step.reactions:
            self.number = None  # whether a reaction runs is up to the run
        after = end
        for r in step.reactions:
            tag = f"{prefix}@on {r.condition} (block line {step.line})"
            if not r.body:  # it only stops the block: mark where it would go on
                self.sections.append(Section(end + 1, end, tag, path, r.line))
            after = max(after, self.steps(r.body, end, path, tag))
        return after


def expand(script: Script) -> Layout:
    """Lay ``script`` out on absolute ticks.

    Counted repeats are expanded; an until/while loop is laid out once and
    labelled as a loop; both branches of an ``@if`` start at the same tick
    (the longer one sets where the script goes on), and so do a block's
    reactions, laid out after the block as possible paths; calls are inlined.

    A timeline that would expand beyond :data:`MAX_TICKS` or :data:`MAX_ITEMS` is laid out
    compactly instead: each counted repeat once, stopping at those limits.
    """
    size = measure(script)
    walk = _Walk(compact=size.ticks > MAX_TICKS or size.items > MAX_ITEMS)
    ticks = walk.steps(script.timeline, 0, script.path, "")
    return Layout(
        tuple(walk.runs),
        tuple(walk.sections),
        ticks,
        tuple(walk.watches),
        tuple(walk.lanes),
        walk.compact,
        walk.cut,
        size.ticks,
    )


def iter_blocks(steps: tuple[Step, ...]) -> Iterator[TBlock]:
    """Every block of ``steps``, in file order, reactions included (not into calls)."""
    return (step for step in iter_steps(steps) if isinstance(step, TBlock))
