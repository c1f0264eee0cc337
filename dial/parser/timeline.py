"""The timeline laid out for display: every run placed on absolute ticks.

:func:`expand` lays a whole checked script out, expanding counted repeats and calls.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from dial.parser.script import Run, Script, Step, TBlock, TIf, TRepeat


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
class Layout:
    runs: tuple[Placed, ...]
    sections: tuple[Section, ...]
    length: int


def expand(script: Script) -> Layout:
    """Lay ``script`` out on absolute ticks.

    Counted repeats are expanded; an until/while loop is laid out once and
    labelled as a loop; both branches of an ``@if`` start at the same tick
    (the longer one sets where the script goes on); calls are inlined.
    """
    runs: list[Placed] = []
    sections: list[Section] = []

    def walk(steps: tuple[Step, ...], offset: int, path: str, label: str) -> int:
        for step in steps:
            if isinstance(step, TBlock):
                runs.extend(Placed(r, offset, path) for r in step.runs)
                sections.append(
                    Section(offset + 1, offset + step.length, label or "block", path, step.line)
                )
                offset += step.length
            elif isinstance(step, TRepeat):
                prefix = f"{label} " if label else ""
                if step.kind == "count":
                    for i in range(step.count):
                        tag = f"{prefix}@repeat {step.count} ({i + 1}/{step.count})"
                        offset = walk(step.body, offset, path, tag)
                else:
                    tag = f"{prefix}@repeat {step.kind} {step.condition} (loop, max {step.count})"
                    offset = walk(step.body, offset, path, tag)
            elif isinstance(step, TIf):
                prefix = f"{label} " if label else ""
                then_end = walk(step.then, offset, path, f"{prefix}@if {step.condition}")
                else_end = walk(step.orelse, offset, path, f"{prefix}@else ({step.condition})")
                offset = max(then_end, else_end)
            else:
                prefix = f"{label} " if label else ""
                offset = walk(
                    step.script.timeline, offset, step.script.path, f"{prefix}@call {step.target}"
                )
        return offset

    length = walk(script.timeline, 0, script.path, "")
    return Layout(tuple(runs), tuple(sections), length)


def iter_blocks(steps: tuple[Step, ...]) -> Iterator[TBlock]:
    """Every block of ``steps``, in file order (not into calls)."""
    for step in steps:
        if isinstance(step, TBlock):
            yield step
        elif isinstance(step, TRepeat):
            yield from iter_blocks(step.body)
        elif isinstance(step, TIf):
            yield from iter_blocks(step.then)
            yield from iter_blocks(step.orelse)
