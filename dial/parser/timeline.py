"""The timeline laid out for display: every run and watched span placed on absolute ticks.

:func:`expand` lays a whole checked script out, expanding counted repeats and calls.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

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
)


@dataclass(frozen=True)
class Section:
    """A stretch of absolute ticks and what it comes from, for display."""

    first: int
    last: int
    label: str
    path: str
    line: int


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
    length: int
    watches: tuple[PlacedWatch, ...] = ()
    lanes: tuple[str, ...] = ()  # every event with a run or a watch, in the order met


def ending_text(step: TResume | TRetry | TAbort) -> str:
    """An ending as written: ``@resume``, ``@retry max N``, ``@abort "MESSAGE"``."""
    if isinstance(step, TResume):
        return "@resume"
    if isinstance(step, TRetry):
        return f"@retry max {step.max}"
    return f'@abort "{step.message}"'


class _Walk:
    """Places every step of a timeline, in order, on absolute ticks."""

    def __init__(self) -> None:
        self.runs: list[Placed] = []
        self.watches: list[PlacedWatch] = []
        self.sections: list[Section] = []
        self.lanes: dict[str, None] = {}

    def steps(self, steps: tuple[Step, ...], offset: int, path: str, label: str) -> int:
        """Place ``steps`` from ``offset``; return the offset after them."""
        prefix = f"{label} " if label else ""
        for step in steps:
            if isinstance(step, TBlock):
                offset = self.block(step, offset, path, label, prefix)
            elif isinstance(step, TRepeat):
                if step.kind == "count":
                    for i in range(step.count):
                        tag = f"{prefix}@repeat {step.count} ({i + 1}/{step.count})"
                        offset = self.steps(step.body, offset, path, tag)
                else:
                    tag = f"{prefix}@repeat {step.kind} {step.condition} (loop, max {step.count})"
                    offset = self.steps(step.body, offset, path, tag)
            elif isinstance(step, TIf):
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
        self.sections.append(Section(offset + 1, end, label or "block", path, step.line))
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
    """
    walk = _Walk()
    length = walk.steps(script.timeline, 0, script.path, "")
    return Layout(
        tuple(walk.runs), tuple(walk.sections), length, tuple(walk.watches), tuple(walk.lanes)
    )


def iter_blocks(steps: tuple[Step, ...]) -> Iterator[TBlock]:
    """Every block of ``steps``, in file order, reactions included (not into calls)."""
    for step in steps:
        if isinstance(step, TBlock):
            yield step
            for r in step.reactions:
                yield from iter_blocks(r.body)
        elif isinstance(step, TRepeat):
            yield from iter_blocks(step.body)
        elif isinstance(step, TIf):
            yield from iter_blocks(step.then)
            yield from iter_blocks(step.orelse)
