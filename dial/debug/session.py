"""A debugging session: where the run pauses, and what the user can do while it is paused.

The session joins the runner through its hooks (:class:`~dial.scheduler.position.Hooks`):
before every tick (``--step``, ``--break tick:N``, ``--break EVENT``), after every period
(stepping by period), after a monitor fires (``--break monitor``), and before every block
(``--save-at block:N FILE``, and a ``save`` asked for while paused). It knows nothing of
MuJoCo: the engine gives it functions that describe the state and write a state file.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from dial.debug.breaks import Break
from dial.debug.console import Console
from dial.parser.script import Run, Script, TBlock
from dial.scheduler.position import TimelinePath
from dial.scheduler.signals import StopRequest

HELP = """\
commands while paused:
  c, continue      run on, to the next breakpoint
  n, tick          run to the start of the next tick
  p, period        run one control period
  s, state         the active runs, latest outcomes, tool pose, fingers, tactile
  save FILE        write a state file at the next block boundary (dial run --resume FILE)
  q, quit          stop the run here (every effector holds; exit status 130)
  h, help          this list
an empty line repeats the last 'tick' or 'period'
"""
COMMANDS = ("continue", "tick", "period", "state", "save", "quit", "help")
_ALIASES = {
    "c": "continue",
    "n": "tick",
    "next": "tick",
    "p": "period",
    "s": "state",
    "q": "quit",
    "h": "help",
    "?": "help",
}


@dataclass
class Session:
    """Hooks for one run: breakpoints, stepping, saving; ``console`` None: no pausing."""

    stop: StopRequest
    console: Console | None = None
    breaks: Sequence[Break] = ()
    step: bool = False
    save_at: tuple[int, Path] | None = None  # (block number, state file)
    save: Callable[[Path, int, TimelinePath, Script], None] = lambda *_: None
    describe: Callable[[], str] = lambda: ""
    where: Callable[[], str] = lambda: ""
    on_pause: Callable[[], None] = lambda: None
    each_period: bool = False
    top: str = ""  # the top script's path: its lines need no file name
    _next_tick: bool = False
    _pending_save: Path | None = None
    _last: str = ""
    _detached: bool = False  # the commands ran out: go on without pausing
    saved: list[tuple[int, Path]] = field(default_factory=list)

    # -- the runner's hooks ----------------------------------------------------------------------
    async def before_block(
        self, number: int, path: TimelinePath, script: Script, block: TBlock
    ) -> None:
        targets = []
        if self.save_at is not None and self.save_at[0] == number:
            targets.append(self.save_at[1])
        if self._pending_save is not None:
            targets.append(self._pending_save)
            self._pending_save = None
        for target in targets:
            self.save(target, number, path, script)
            self.saved.append((number, target))
            self._say(f"saved the state before block {number} (line {block.line}) to {target}\n")

    async def before_tick(self, tick: int, script: Script, starting: Sequence[Run]) -> None:
        reasons = []
        if self._next_tick or self.step:
            reasons.append("step")
        reasons += [f"--break tick:{tick}" for b in self.breaks if b.tick == tick]
        names = {b.event for b in self.breaks if b.event is not None}
        # A called script's line is named with its file: "line 70" alone reads as the top's.
        where = "line " if script.path == self.top else f"{Path(script.path).name}:"
        reasons += [f"--break {r.event} ({where}{r.line})" for r in starting if r.event in names]
        self._next_tick = False
        if reasons:
            await self.pause(", ".join(reasons))

    async def after_period(self, periods: int) -> None:
        self.each_period = False
        await self.pause("one period")

    async def after_monitor(self, event: str, condition: str, tick: int) -> None:
        if any(b.monitor for b in self.breaks):
            await self.pause(f"--break monitor ('@on {condition}' fired)")

    # -- paused ---------------------------------------------------------------------------------
    async def pause(self, reason: str) -> None:
        """Read and do commands until one lets the run go on."""
        if self.console is None or self._detached:
            return
        self.on_pause()
        self.console.write(f"paused at {self.where()}: {reason}\n")
        while self.stop.signal is None:
            line = await self.console.read("(dial) ", self.stop)
            if line is None:
                self._detached = True
                self.console.write("end of commands: the run goes on without pausing\n")
                return
            if await self._command(line):
                return

    async def _command(self, line: str) -> bool:
        """Do one command; True when the run should go on."""
        assert self.console is not None
        word, _, rest = (line or self._last).partition(" ")
        name = _ALIASES.get(word, word)
        if name in ("tick", "period"):
            self._last = name
        if name == "continue":
            return True
        if name == "tick":
            self._next_tick = True
            return True
        if name == "period":
            self.each_period = True
            return True
        if name == "state":
            self.console.write(self.describe())
        elif name == "save":
            return self._ask_save(rest.strip())
        elif name == "quit":
            self.stop.request("quit")
            return True
        elif name == "help" or not word:
            self.console.write(HELP)
        else:
            self.console.write(f"unknown command '{word}'; commands: {', '.join(COMMANDS)}\n")
        return False

    def _ask_save(self, target: str) -> bool:
        assert self.console is not None
        if not target:
            self.console.write("save needs a file: save FILE\n")
        else:
            if self._pending_save is not None:
                self.console.write(f"(instead of {self._pending_save}) ")
            self._pending_save = Path(target)
            self.console.write(
                f"the state will be saved to {target} at the next block boundary (if the run "
                "starts another block)\n"
            )
        return False

    @property
    def unsaved(self) -> Path | None:
        """A ``save`` asked for while paused that no block boundary came to write."""
        return self._pending_save

    def _say(self, text: str) -> None:
        if self.console is not None:
            self.console.write(text)
