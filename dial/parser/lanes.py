"""A script's event lanes: which events it runs, in script order, and which runs hold.

What a recording needs to draw the script's diagram as it happened
(:mod:`dial.recording.lanes`), worked out from the compiled program alone. The engine logs
it (a ``lanes`` record, with ``--log-states``) so that a replay draws the same lanes.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from dial.parser.script import Script, Step, TBlock, TCall, TIf, TRepeat

Key = tuple[str, ...]  # (event,) in the script run, (script stem, event) in a called one


@dataclass(frozen=True)
class LanePlan:
    """A script's lanes: ``order`` in script order, the ``condition_only`` events, and
    ``holds``: (script path, "" for the script run; line; start block tick) -> held ticks."""

    order: tuple[Key, ...]
    condition_only: frozenset[Key] = frozenset()
    holds: Mapping[tuple[str, int, int], int] = field(default_factory=dict)

    @classmethod
    def from_script(cls, script: Script) -> LanePlan:
        order: list[Key] = []
        holds: dict[tuple[str, int, int], int] = {}
        only: set[Key] = set()
        _plan(script, (), "", order, holds, only, set())
        return cls(tuple(order), frozenset(only), holds)

    def as_record(self) -> dict[str, Any]:
        """The plan as a log record (``kind: lanes``), so that a replay draws the same lanes."""
        return {
            "kind": "lanes",
            "order": [list(k) for k in self.order],
            "condition_only": sorted(list(k) for k in self.condition_only),
            "holds": [[s, line, start, n] for (s, line, start), n in sorted(self.holds.items())],
        }

    @classmethod
    def from_record(cls, record: Mapping[str, Any]) -> LanePlan:
        """The plan from its log record (read back as JSON)."""
        return cls(
            tuple(tuple(k) for k in record.get("order", [])),
            frozenset(tuple(k) for k in record.get("condition_only", [])),
            {(str(s), int(line), int(start)): int(n) for s, line, start, n in record["holds"]},
        )


def _plan(
    script: Script,
    group: Key,
    path: str,
    order: list[Key],
    holds: dict[tuple[str, int, int], int],
    only: set[Key],
    seen: set[str],
) -> None:
    """Append ``script``'s lanes to ``order``, then those of the scripts it calls."""
    firsts: dict[Key, int] = {}
    calls: dict[str, tuple[int, Script]] = {}

    def note(event: str, line: int) -> None:
        key = (*group, event)
        firsts[key] = min(firsts.get(key, line), line)

    def walk(steps: Iterable[Step]) -> None:
        for step in steps:
            if isinstance(step, TBlock):
                for run in step.runs:
                    note(run.event, run.line)
                    if run.hold_end > run.exec_end:
                        holds[(path, run.line, run.start)] = run.hold_end - run.exec_end
                for watch in step.watches:
                    note(watch.event, watch.line)
                for on in step.reactions:
                    note(on.condition.event, on.line)
                    walk(on.body)
            elif isinstance(step, TRepeat | TIf):
                if step.condition is not None:
                    note(step.condition.event, step.line)
                walk(step.body if isinstance(step, TRepeat) else (*step.then, *step.orelse))
            elif isinstance(step, TCall):
                calls.setdefault(step.script.path, (step.line, step.script))

    seen.add(script.path)
    walk(script.timeline)
    only.update((*group, e) for e in script.condition_only)
    items: list[tuple[int, Key | Script]] = [(line, key) for key, line in firsts.items()]
    items += [(line, callee) for line, callee in calls.values()]
    for _, item in sorted(items, key=lambda it: it[0]):
        if isinstance(item, tuple):
            order.append(item)
        elif item.path not in seen:  # a callee's lanes, grouped where it is first called
            _plan(item, (Path(item.path).stem,), item.path, order, holds, only, seen)
