"""``--break EVENT|tick:N|monitor``: where a run pauses."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from dial.errors import OptionError

FORMS = "EVENT, tick:N or monitor"


@dataclass(frozen=True)
class Break:
    """Pause before a run of ``event`` starts, at the start of absolute tick ``tick``, or
    after a monitor fires (``monitor``). One of the three is set."""

    event: str | None = None
    tick: int | None = None
    monitor: bool = False

    def __str__(self) -> str:
        if self.event is not None:
            return self.event
        return f"tick:{self.tick}" if self.tick is not None else "monitor"


def parse_break(text: str, events: Iterable[str]) -> Break:
    """One ``--break`` value; ``events``: the events of the script and the scripts it calls."""
    if text == "monitor":
        return Break(monitor=True)
    if text.startswith("tick:"):
        digits = text[5:]
        if not (digits.isascii() and digits.isdigit() and len(digits) <= 9 and int(digits) >= 1):
            raise OptionError(f"--break {text}: expected tick:N with N a tick from 1 ({FORMS})")
        return Break(tick=int(digits))
    known = sorted(set(events))
    if text not in known:
        raise OptionError(
            f"--break {text}: no event '{text}' in the script (expected {FORMS}; "
            f"events: {', '.join(known)})"
        )
    return Break(event=text)
