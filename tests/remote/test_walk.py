"""``--split block``'s walk (dial/remote/walk.py) against a robot of the test's own, which
reports one command at a time only when the walk waits: a block that depends on no
pending outcome is sent ahead; a decision waits for the outcome it needs, and what follows
it is tagged the lead after the tick the robot reported."""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import trio

import dial
from dial.remote.protocol import Message
from dial.remote.walk import Walker

LEAD = 4  # ticks


@dataclass
class Sent:
    seq: int
    type: str
    tick: int
    after: int
    seen: int  # how many results the robot had reported when it was sent
    fields: dict[str, object]


@dataclass
class Channel:
    sent: list[Sent] = field(default_factory=list)
    results: dict[int, Message] = field(default_factory=dict)

    async def command(self, type_: str, /, **fields: object) -> int:
        seq = len(self.sent) + 2  # 1 was the 'open'
        tick, after = fields.pop("tick"), fields.pop("after")
        assert isinstance(tick, int) and isinstance(after, int)
        self.sent.append(Sent(seq, type_, tick, after, len(self.results), fields))
        return seq


@dataclass
class Station:
    """The operator as the walk sees it; the robot runs every command on time, a watched
    block two ticks longer than its length, and senses 'ringing' ``ringing`` times."""

    ringing: int
    channel: Channel = field(default_factory=Channel)
    latest: dict[tuple[str, str], str] = field(default_factory=dict)

    @property
    def results(self) -> dict[int, Message]:
        return self.channel.results

    def link(self, kind: str, /, **fields: object) -> None:
        raise AssertionError("the walk writes no link record")

    async def result_of(self, seq: int) -> Message:
        raise AssertionError("the walk waits through next_report")

    async def next_report(self) -> None:
        """The robot reports the first command it has not reported."""
        await trio.lowlevel.checkpoint()
        cmd = next(c for c in self.channel.sent if c.seq not in self.results)
        fields: dict[str, object] = {"seq": cmd.seq, "id": f"c{cmd.seq}"}
        if cmd.type == "block":
            block = cmd.fields["block"]
            assert isinstance(block, dict)
            extra = 2 if block["reactions"] or block["watches"] else 0
            fields["tick"] = cmd.tick + int(block["length"]) - 1 + extra
        else:
            fields["tick"] = cmd.tick - 1  # tested before its tick
            fields["value"] = self.ringing > 0
            self.ringing -= 1
        self.results[cmd.seq] = Message("result", fields)


def _walk(name: str, ringing: int) -> list[Sent]:
    script = dial.load(name)
    op = Station(ringing)

    async def main() -> None:
        walker = Walker(op, 1, LEAD)  # type: ignore[arg-type]
        await walker.walk(script, script.timeline)
        await walker.end(None)

    trio.run(main)
    return op.channel.sent


def _line(cmd: Sent) -> int:
    block = cmd.fields.get("block")
    return int(block["line"]) if isinstance(block, dict) else int(str(cmd.fields["line"]))


def test_blocks_are_sent_ahead_and_decisions_wait_for_their_outcome() -> None:
    sent = _walk("pour.dial", ringing=1)
    assert [c.after for c in sent] == [1] + [c.seq for c in sent[:-1]]  # one chain
    assert [(c.type, _line(c) if c.type != "end" else 0) for c in sent] == [
        ("block", 75), ("test", 79), ("block", 80), ("test", 79), ("block", 83),
        ("test", 86), ("block", 90), ("block", 97), ("test", 105), ("block", 109),
        ("block", 136), ("end", 0),
    ]  # fmt: skip
    # Sent ahead: pour's first block and the test after it go out before any report, and
    # so do the three blocks after the second loop and the test that follows them.
    assert [c.seen for c in sent[:2]] == [0, 0]
    assert sent[6].seen == sent[7].seen == sent[8].seen
    for before, after in itertools.pairwise(sent):
        if before.type == "test" or before.seq == sent[9].seq:  # a decision, a watched block
            # It waits for the robot's report and is tagged the lead after its tick.
            assert after.seen > before.seen, (before, after)
            assert after.tick == _reported_tick(before) + 1 + LEAD, (before, after)
        else:
            assert after.seen == before.seen, (before, after)  # no wait: sent at once
            block = before.fields["block"]
            assert isinstance(block, dict)
            assert after.tick == before.tick + int(block["length"])  # tagged back to back


def _reported_tick(cmd: Sent) -> int:
    if cmd.type == "test":
        return cmd.tick - 1
    block = cmd.fields["block"]
    assert isinstance(block, dict)
    return cmd.tick + int(block["length"]) - 1 + 2


def test_a_loop_that_the_robot_senses_longer_sends_its_body_again_after_each_report() -> None:
    sent = _walk("pour.dial", ringing=3)
    tests = [c for c in sent if c.type == "test"]
    assert [_line(c) for c in tests][:4] == [79, 79, 79, 79]  # three times ringing, then not
    bodies = [c for c in sent if c.type == "block" and _line(c) == 80]
    assert len(bodies) == 3
    seen = [c.seen for c in tests[:4]]
    assert seen == sorted(set(seen))  # each test waits for the one before it
