"""Parser and checker behaviour beyond the golden files."""

from __future__ import annotations

from pathlib import Path

import pytest

from dial.errors import ScriptError, Span
from dial.instructions.types import Contact
from dial.parser import TBlock, TCall, TIf, TRepeat, check_text, parse, parse_partial
from dial.parser.ast import Block, Condition
from dial.parser.script import TAbort, TOn, TResume, TRetry, Watch

HEAD = '% go puma_command "moves above"\n% open hand_pose "open_hand"\n'


def test_block_tick_one_is_the_leftmost_diagram_column() -> None:
    # As in the paper's Fig. 10: preshape drawn five columns right of to_bulb starts at tick 6.
    program = parse(HEAD + "go   #=========\nopen      #----\n")
    block = program.body[0]
    assert isinstance(block, Block)
    runs = {line.event: line.runs[0] for line in block.lines}
    assert (runs["go"].start, runs["go"].exec_end, runs["go"].hold_end) == (1, 10, 10)
    assert (runs["open"].start, runs["open"].exec_end, runs["open"].hold_end) == (6, 6, 10)


def test_blank_line_and_directive_end_blocks_but_comments_do_not() -> None:
    script = check_text(HEAD + "go #\n// note\n/* x */\nopen #\n\ngo #\n@tick 1\nopen #\n", "t")
    assert script is not None
    blocks = [s for s in script.timeline if isinstance(s, TBlock)]
    assert [len(b.runs) for b in blocks] == [2, 1, 1]


def test_a_new_hash_on_the_same_line_starts_a_new_run() -> None:
    program = parse(HEAD + "go #==#-- #\n")
    block = program.body[0]
    assert isinstance(block, Block)
    line = block.lines[0]
    assert [(r.start, r.exec_end, r.hold_end) for r in line.runs] == [
        (1, 3, 3),
        (4, 4, 6),
        (8, 8, 8),
    ]


def test_repeat_if_and_call_compile_to_steps(tmp_path: Path) -> None:
    sub = tmp_path / "sub.dial"
    sub.write_text("% g get_joints\ng #\n")
    main = tmp_path / "main.dial"
    main.write_text(
        HEAD + "% t tactile_contact finger=index\n"
        "@repeat 3\ngo #\n@end\n@repeat while t max 7\ngo #\n@end\n"
        "@if !t\nopen #\n@else\ngo #\n@end\n@call sub.dial\n"
    )
    script = check_text(main.read_text(), str(main))
    assert script is not None
    rep, loop, branch, call = script.timeline
    assert isinstance(rep, TRepeat) and (rep.kind, rep.count) == ("count", 3)
    assert isinstance(loop, TRepeat) and (loop.kind, loop.count, str(loop.condition)) == (
        "while",
        7,
        "t",
    )
    assert isinstance(branch, TIf) and branch.condition.negated
    assert isinstance(call, TCall) and "g" in call.script.events
    assert script.condition_only == {"t"}


def test_repeat_max_defaults_to_100() -> None:
    script = check_text(HEAD + "% t get_joints\n@repeat until t\ngo #\n@end\n", "t")
    assert script is not None
    assert isinstance(script.timeline[0], TRepeat) and script.timeline[0].count == 100


def test_all_errors_are_reported_in_one_pass() -> None:
    text = '% a hand_pos x\n% b grasp_force "0x0666_0x0222 400"\nc #\n@end\n'
    with pytest.raises(ScriptError) as info:
        check_text(text, "many.dial")
    lines = [d.span.line for d in info.value.diagnostics]
    assert lines == [1, 2, 3, 4]


def test_program_equality_ignores_spacing() -> None:
    a = parse('% go  puma_command "moves   above"\n\ngo   #==\n')
    b = parse('% go puma_command "moves above"\n\ngo #==\n')
    assert a == b
    assert a != parse('% go puma_command "moves above"\n\ngo #=\n')


def test_crlf_line_endings_parse_like_lf() -> None:
    assert parse(HEAD.replace("\n", "\r\n") + "go #=\r\n") == parse(HEAD + "go #=\n")


WATCH_HEAD = (
    "% down arm_move 0 0 -0.03 frame=world\n"
    "% up arm_move 0 0 0.01 frame=world\n"
    "% touch tactile_contact finger=index\n"
    "% held force_contact finger=thumb\n"
)


def test_watched_spans_compile_to_watches_not_runs() -> None:
    script = check_text(
        WATCH_HEAD + "down  #====\ntouch   ~~ ~~~.\nheld  ~\n@on touch\n@end\n@on !held\n@end\n",
        "w.dial",
    )
    block = script.timeline[0]
    assert isinstance(block, TBlock)
    assert [r.event for r in block.runs] == ["down"]
    touch, held = Contact("tactile", 0, 0.0001), Contact("force", 3, 0.5)
    assert block.watches == (
        Watch("held", 7, 1, 1, held),
        Watch("touch", 6, 3, 4, touch),
        Watch("touch", 6, 6, 8, touch),
    )
    assert block.watches[1].span == Span(6, 9, 11)
    assert block.length == 9  # the '~' ticks and the trailing '.' count
    assert [str(r.condition) for r in block.reactions] == ["touch", "!held"]
    assert "touch" not in script.condition_only and "held" not in script.condition_only


def test_reaction_bodies_compile_with_their_endings() -> None:
    text = WATCH_HEAD + (
        "down  #====\ntouch ~~~\n"
        "@on touch\nup    #\nheld  ~\n@on held\n@resume\n@end\n"
        '@repeat 2\nup #\n@if held\n@abort "slipped  twice"\n@end\n@end\n@retry\n@end\n'
        "@on !touch\n@retry max 7\n@end\n"
    )
    block = check_text(text, "w.dial").timeline[0]
    assert isinstance(block, TBlock)
    first, second = block.reactions
    inner, loop, retry = first.body
    held = Contact("force", 3, 0.5)
    assert isinstance(inner, TBlock) and inner.watches == (Watch("held", 9, 1, 1, held),)
    assert inner.reactions == (TOn(Condition("held", False), (TResume(11),), 10),)
    assert isinstance(loop, TRepeat) and isinstance(loop.body[1], TIf)
    assert loop.body[1].then == (TAbort("slipped twice", 16),)
    assert retry == TRetry(3, 19)
    assert second == TOn(Condition("touch", True), (TRetry(7, 22),), 21)


def test_an_on_may_follow_a_broken_block_without_a_second_error() -> None:
    text = WATCH_HEAD + "down  #=x\ntouch ~~~\n@on touch\n@end\n"
    with pytest.raises(ScriptError) as info:
        check_text(text, "w.dial")
    assert [d.span.line for d in info.value.diagnostics] == [5]
    # A broken block inside the first reaction does not make the second one an error.
    text = WATCH_HEAD + "down  #=x\ntouch ~~~\n@on touch\nup #x\n@end\n@on !touch\n@end\n"
    with pytest.raises(ScriptError) as info:
        check_text(text, "w.dial")
    assert [d.span.line for d in info.value.diagnostics] == [5, 8]


def test_a_block_after_a_broken_one_is_still_read() -> None:
    with pytest.raises(ScriptError) as info:
        check_text(HEAD + "go #x\n\ngo #\nopen #\n\nopen #\n", "t")
    assert [d.span.line for d in info.value.diagnostics] == [3]
    program, _ = parse_partial(HEAD + "go #x\n\ngo #\n// c\nopen #\n\nopen #\n")
    assert [len(b.lines) for b in program.body if isinstance(b, Block)] == [2, 1]
