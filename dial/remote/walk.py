"""What the operator sends: the whole script (``--split script``), or the timeline walked
block by block (``--split block``, NASREM level 4).

The walk follows the runner's (blocks, ``@repeat``, ``@if``, ``@call``) and tags every
command with the tick it must start at. A block whose length is known (no watched span,
so no reaction that could end it early or run on) moves the next tick on by its length, so
the next block can be sent at once, ahead of time. A condition is tested at the robot, and
the branch or loop waits for its result; so does whatever follows a watched block. The
command after such a wait is tagged ``lead`` ticks after the tick the robot reported:
enough for it to cross the link. A command refused ``late`` is sent again, with those after
it, ``lead`` ticks after the robot's tick, and the lead doubles.
"""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path
from typing import Protocol

from dial.errors import DialError
from dial.parser.script import (
    Script,
    Step,
    TBlock,
    TCall,
    TIf,
    TRepeat,
    iter_steps,
    scripts_of,
)
from dial.remote.blocks import describe
from dial.remote.channel import Channel
from dial.remote.options import OperatorOptions
from dial.remote.protocol import Message


class Station(Protocol):
    """What the walk needs of the operator: the channel, the options, the reports."""

    channel: Channel
    options: OperatorOptions
    results: dict[int, Message]  # by command seq: each command's result or refusal
    latest: dict[tuple[str, str], str]  # (script, event) -> its latest outcome, reported

    def link(self, kind: str, /, **fields: object) -> None: ...

    async def result_of(self, seq: int) -> Message: ...

    async def next_report(self) -> None: ...


LEAD_TRIPS = 1.5  # the default lead: this many round trips and LEAD_MARGIN_S,
LEAD_MARGIN_S = 0.2  # s
LEAD_GRID_S = 0.5  # rounded up to 0.5, 1, 2, 4, 8... s when the round trip is measured
ENVELOPE_BYTES = 160  # a block command's fields besides its block, about


async def run_split(script: Script, op: Station) -> None:
    """Send the script whole, or open a block session and walk its timeline."""
    ch, tick = op.channel, op.options.tick
    rtt = await ch.measure_rtt()
    op.link("rtt", seconds=round(rtt, 4))
    if op.options.split == "script":
        seq = await ch.command("run", tick=1, after=0, script=upload(script), tick_length=tick)
        _accepted(await op.result_of(seq))
        return
    seq = await ch.command("open", script=upload(script), tick_length=tick)
    _accepted(await op.result_of(seq))
    walker = Walker(op, seq, lead_ticks(op, rtt, script))
    try:
        await walker.walk(script, script.timeline)
    except _Max as e:
        await walker.end(str(e))
        return
    await walker.end(None)


def _accepted(result: Message) -> None:
    """The robot took the script (else a one-line error; a rejected script's diagnostics
    are the operator's message already)."""
    if result.type == "refused" and result.text("code") != "rejected":
        raise DialError(f"the robot refused the script: {result.text('message')}")


def lead_ticks(op: Station, rtt: float, script: Script) -> int:
    """``--lead`` in ticks of the robot's paced time (default: :func:`default_lead`),
    logged, and said unless ``--quiet`` so that a user can pin it."""
    pace = op.channel.robot.get("pace", 1.0)
    wall_per_tick = op.options.tick * (float(pace) if isinstance(pace, int | float) else 1.0)
    given = op.options.lead
    seconds, why = (given, "--lead") if given is not None else default_lead(op, rtt, script)
    ticks = max(1, math.ceil(round(seconds / wall_per_tick, 9)))
    op.link("lead", seconds=round(seconds, 4), ticks=ticks, source=why)
    if given is None and not op.options.quiet:
        print(
            f"dial: --split block: the lead is {seconds:g} s ({ticks} ticks at the robot), "
            f"{why}; '--lead {seconds:g}' gives it again",
            file=sys.stderr,
        )
    return ticks


def default_lead(op: Station, rtt: float, script: Script) -> tuple[float, str]:
    """LEAD_TRIPS round trips and LEAD_MARGIN_S (s), and where the round trip comes from.

    With ``--link`` the round trip is the emulated link's worst, two delays and two
    jitters, plus sending the script's largest block at its bandwidth: the same in every
    run. Without, it is the ping measured at connect, which jitter and load vary from run
    to run: the lead is then rounded up to the grid 0.5, 1, 2, 4... s, so that two runs
    through the same link tag the same ticks (unless the round trip lies at a step).
    """
    spec = op.options.link
    if spec is not None:
        trip = 2.0 * (spec.delay + spec.jitter)
        if spec.bandwidth is not None:
            trip += 8.0 * (largest_block(script) + ENVELOPE_BYTES) / spec.bandwidth
        return round(LEAD_TRIPS * trip + LEAD_MARGIN_S, 3), "from the --link spec"
    seconds = LEAD_GRID_S
    while seconds < LEAD_TRIPS * rtt + LEAD_MARGIN_S:
        seconds *= 2.0
    return seconds, f"from the round trip of {rtt:.3f} s measured at connect"


def largest_block(script: Script) -> int:
    """The bytes of the script's largest block description (of it and what it calls)."""
    return max(
        (
            len(json.dumps(describe(s, step)))
            for s in scripts_of(script)
            for step in iter_steps(s.timeline)
            if isinstance(step, TBlock)
        ),
        default=0,
    )


def upload(script: Script) -> dict[str, object]:
    """The script and every script it calls, as files relative to the script's folder."""
    base = Path(script.path).parent
    files: dict[str, str] = {}
    for s in scripts_of(script):
        name = os.path.relpath(s.path, base).replace(os.sep, "/")
        if name.startswith(".."):
            raise DialError(f"'{s.path}' lies outside the script's folder: it cannot be sent")
        files[name] = Path(s.path).read_text(encoding="utf-8")
    return {"path": script.path, "main": Path(script.path).name, "files": files}


class _Max(Exception):
    """A loop reached its max at the operator: the run ends with this error."""


class Walker:
    """The operator's walk of a timeline, as commands tagged with ticks."""

    def __init__(self, op: Station, after: int, lead: int) -> None:
        self.op, self.after, self.lead = op, after, lead
        self.next = 1  # the tick the next command starts at, unless it waits on a result
        self.waiting: int | None = None  # the command whose result tells the next tick
        # Commands sent since the last result, to send again if one is refused late:
        # (seq, type, tick, fields).
        self.chain: list[tuple[int, str, int, dict[str, object]]] = []
        self.renamed: dict[int, int] = {}  # a refused command's seq -> its re-sent seq

    async def walk(self, script: Script, steps: tuple[Step, ...]) -> None:
        for step in steps:
            if isinstance(step, TBlock):
                length = None if step.reactions else step.length
                body = describe(script, step)["block"]
                await self._send("block", length, script=script.path, block=body)
            elif isinstance(step, TRepeat):
                await self._repeat(script, step)
            elif isinstance(step, TIf):
                then = await self.test(script, step)
                await self.walk(script, step.then if then else step.orelse)
            elif isinstance(step, TCall):
                await self.walk(step.script, step.script.timeline)

    async def _repeat(self, script: Script, step: TRepeat) -> None:
        for _ in range(step.count):
            if step.kind == "while" and not await self.test(script, step):
                return
            await self.walk(script, step.body)
            if step.kind == "until" and await self.test(script, step):
                return
        if step.kind == "count" or (step.kind == "while" and not await self.test(script, step)):
            return
        raise _Max(
            f"'@repeat {step.kind} {step.condition}' on line {step.line} of {script.path} "
            f"reached its max of {step.count} iterations"
        )

    async def test(self, script: Script, step: TIf | TRepeat) -> bool:
        """A condition, tested at the robot at its tick. Its value is known here when the
        robot has reported its event's latest outcome and no command on its way can change
        it: then the walk goes on at once; else it waits for the robot's value."""
        known = self._known(script, step)
        seq = await self._send(
            "test",
            None if known is None else 0,
            script=script.path,
            line=step.line,
            condition=str(step.condition),
        )
        if known is not None:
            return known
        return (await self._result(seq)).fields.get("value") is True

    def _known(self, script: Script, step: TIf | TRepeat) -> bool | None:
        cond = step.condition
        assert cond is not None
        if cond.event in script.condition_only:
            return None  # sensed at the robot, now
        mention = json.dumps(cond.event)
        for seq, type_, _, fields in self.chain:
            on_its_way = seq not in self.op.results and type_ == "block"
            if on_its_way and mention in json.dumps(fields.get("block")):
                return None  # a block on its way runs or watches the event
        outcome = self.op.latest.get((script.path, cond.event))
        return (outcome == "done") != cond.negated

    async def end(self, error: str | None) -> None:
        await self._send("end", 0, **({} if error is None else {"error": error}))

    async def _send(self, type_: str, length: int | None, **fields: object) -> int:
        if self.waiting is not None:
            result = await self._result(self.waiting)
            self.next = result.integer("tick") + 1 + self.lead
            self.waiting = None
            self.chain.clear()
        tick = self.next
        seq = await self.op.channel.command(type_, tick=tick, after=self.after, **fields)
        self.chain.append((seq, type_, tick, fields))
        self.after = seq
        if length is None:
            self.waiting = seq
        else:
            self.next = tick + length
        return seq

    async def _result(self, seq: int) -> Message:
        """Wait for command ``seq``'s result; meanwhile, a command of the chain before it
        refused ``late`` is sent again with those after it (``seq`` then names the copy)."""
        while True:
            seq = self.renamed.get(seq, seq)
            refused = self._refused()
            if refused is not None:
                await self._resend(refused.integer("seq"), refused)
                continue
            result = self.op.results.get(seq)
            if result is not None and result.type != "refused":
                return result
            await self.op.next_report()

    def _refused(self) -> Message | None:
        """The first command of the chain that the robot refused, if any."""
        for old, *_ in self.chain:
            result = self.op.results.get(old)
            if result is not None and result.type == "refused":
                if result.text("code") not in ("late", "dropped"):
                    raise DialError(f"the robot refused command {old}: {result.text('message')}")
                return result
        return None

    async def _resend(self, seq: int, refused: Message) -> None:
        """Send the late command and those chained after it again, later by one lead more."""
        self.lead *= 2
        at = next(i for i, c in enumerate(self.chain) if c[0] == seq)
        again = self.chain[at:]
        shift = refused.integer("tick") + 1 + self.lead - again[0][2]
        self.after = refused.integer("after")  # the last command the robot ran
        self.chain = self.chain[:at]
        for old, type_, tick, fields in again:
            new = await self.op.channel.command(
                type_, tick=tick + shift, after=self.after, **fields
            )
            self.chain.append((new, type_, tick + shift, fields))
            self.renamed[old] = new
            self.after = new
            if self.waiting == old:
                self.waiting = new
        self.next += shift
