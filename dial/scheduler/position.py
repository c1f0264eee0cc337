"""Where a run is in its timeline, and the seam where a debugger or a state saver joins it.

A :data:`TimelinePath` names a step exactly, also inside ``@repeat``, ``@if``, ``@call`` and an
``@on`` reaction: one :class:`Frame` per level of the walk. Saving a run at a block
boundary keeps its path; resuming walks straight back down it (DESIGN 6.1).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple, Protocol

from dial.parser.script import Run, Script, TBlock

if TYPE_CHECKING:
    from dial.scheduler.primitive import Outcome


class Frame(NamedTuple):
    """One level of the walk: the step at index ``step`` of its statement list.

    ``detail``: for ``@repeat`` the iteration (0-based), for ``@if`` the branch taken (0 then,
    1 else), for a block how often it has been retried. ``reaction``: for a block whose
    ``@on`` body is running, that reaction's index in ``TBlock.reactions``; else -1. A
    ``@call`` frame is followed by the frames inside the callee.
    """

    step: int
    detail: int = 0
    reaction: int = -1


TimelinePath = tuple[Frame, ...]


@dataclass(frozen=True)
class Resume:
    """What the runner needs to go on from a saved block boundary."""

    path: TimelinePath
    blocks: int  # blocks started before the saved one
    periods: int
    clock: int
    tick: int
    latest: Mapping[tuple[str, str], Outcome] = field(default_factory=dict)
    counts: Mapping[str, int] = field(default_factory=dict)


class Hooks(Protocol):
    """Where a debugger or a state saver joins a run. Each hook may pause the run (await)."""

    each_period: bool  # call after_period after every control period (a debugger stepping)

    async def before_block(
        self, number: int, path: TimelinePath, script: Script, block: TBlock
    ) -> None:
        """Before the ``number``-th block the run starts (1-based, repeats and retries too)."""

    async def before_tick(self, tick: int, script: Script, starting: Sequence[Run]) -> None:
        """At the start of absolute tick ``tick``, before its runs (``starting``) start."""

    async def after_period(self, periods: int) -> None:
        """After a control period, when ``each_period`` is set."""

    async def after_monitor(self, event: str, condition: str, tick: int) -> None:
        """After a monitor preempted its block, before the reaction starts."""
