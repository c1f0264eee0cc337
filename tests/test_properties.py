"""Property tests: the parser never raises anything but ScriptError, and fmt is safe."""

from __future__ import annotations

from collections.abc import Callable

import pytest

pytest.importorskip(
    "hypothesis", reason="the 'test' extra is not installed: pip install -e '.[test]'"
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from dial.errors import ScriptError
from dial.parser import check_text, parse, words
from dial.parser.ast import Param
from dial.parser.fmt import format_text
from dial.parser.words import WordError

DEFINITIONS = [
    '% go puma_command "moves above"',
    '% back  puma_command   "depart 50mm"',
    '% open hand_pose "open_hand"',
    "% pt  hand_pose point fingers=0x000F",
    '% grab grasp_force "0x0666_0x0222 4N" timeout=2s',
    "% touch tactile_contact finger=index threshold=0.1mm  // wait for it",
    "% down guarded_move finger=index 0 0 -2cm until=tactile,force:1N",
    "% rec record_contact finger=index into=s",
    "% fit fit_plane s",
    "% j get_joints",
]
EVENTS = ["go", "back", "open", "pt", "grab", "touch", "down", "rec", "fit", "j", "zz"]
DIRECTIVES = [
    "@repeat 2",
    "@repeat until touch max 5",
    "@repeat while !j",
    "@if grab",
    "@else",
    "@end",
    "@tick 0.2",
    "@scene ./nowhere",
    "@on touch",
    "@on !touch",
    "@resume",
    "@retry",
    "@retry max 2",
    '@abort "it  slipped"',
]
ENDINGS = ["", "@resume", "@retry max 4", "@retry", '@abort "lost it"']
COMMENTS = ["// a comment", "/* one line */", "/* two", "lines */", "//  1234567890", ""]


@st.composite
def diagrams(draw: st.DrawFn) -> str:
    out = " " * draw(st.integers(0, 6))
    for _ in range(draw(st.integers(1, 3))):
        out += "#" + "=" * draw(st.integers(0, 4)) + "-" * draw(st.integers(0, 3))
        out += draw(st.sampled_from(["", " ", "  ", ".", ". "]))
    return out.rstrip()


@st.composite
def watched(draw: st.DrawFn) -> str:
    out = " " * draw(st.integers(0, 6))
    for _ in range(draw(st.integers(1, 2))):
        out += "~" * draw(st.integers(1, 5)) + draw(st.sampled_from(["", " ", ".", " . "]))
    return out.rstrip()


@st.composite
def reaction(draw: st.DrawFn) -> list[str]:
    """A block with a watched line, and an ``@on`` for it (sometimes with a nested one)."""
    gap = " " * draw(st.integers(1, 4))
    lines = ["go" + gap + draw(diagrams()), "touch" + gap + draw(watched())]
    lines.append(draw(st.sampled_from(["@on touch", "@on !touch"])))
    if draw(st.booleans()):
        lines += ["back " + draw(diagrams())]
        if draw(st.booleans()):
            lines += ["touch  " + draw(watched()), "@on !touch", "@resume", "@end"]
    ending = draw(st.sampled_from(ENDINGS))
    return [*lines, *([ending] if ending else []), "@end"]


@st.composite
def scripts(draw: st.DrawFn) -> str:
    lines: list[str] = []
    for _ in range(draw(st.integers(1, 14))):
        kind = draw(st.sampled_from(["def", "exec", "exec", "exec", "dir", "comment", "react"]))
        if kind == "react":
            lines += draw(reaction())
        elif kind == "def":
            lines.append(draw(st.sampled_from(DEFINITIONS)))
        elif kind == "exec":
            name = draw(st.sampled_from(EVENTS))
            gap = " " * draw(st.integers(1, 8))
            tail = draw(st.sampled_from(["", "", "  // note", " /* c */"]))
            marks = draw(st.one_of(diagrams(), diagrams(), watched()))
            lines.append(name + gap + marks + tail)
        elif kind == "dir":
            lines.append(draw(st.sampled_from(DIRECTIVES)))
        else:
            lines.append(draw(st.sampled_from(COMMENTS)))
    return "\n".join(lines) + "\n"


ALPHABET = st.sampled_from(
    [*'#=-~. \t\n%@/*"_=!x0aZ:,', "\r\n", "0x", "@end", "@on touch", "@retry", "é"]
)


@st.composite
def mutated(draw: st.DrawFn) -> str:
    text = draw(scripts())
    for _ in range(draw(st.integers(1, 4))):
        i = draw(st.integers(0, len(text)))
        op = draw(st.sampled_from(["insert", "delete", "replace"]))
        ch = draw(ALPHABET)
        if op == "insert":
            text = text[:i] + ch + text[i:]
        elif op == "delete":
            text = text[:i] + text[i + 1 :]
        else:
            text = text[:i] + ch + text[i + 1 :]
    return text


SETTINGS = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _check_raises_only_script_errors(text: str) -> None:
    try:
        check_text(text, "prop.dial")
    except ScriptError as e:
        assert e.diagnostics
        for d in e.diagnostics:
            assert d.span.line >= 1 and d.span.col >= 1, d
            d.render()


@SETTINGS
@given(scripts())
def test_generated_scripts_raise_only_script_errors(text: str) -> None:
    _check_raises_only_script_errors(text)


@SETTINGS
@given(mutated())
def test_mutated_scripts_raise_only_script_errors(text: str) -> None:
    _check_raises_only_script_errors(text)


@SETTINGS
@given(st.text(max_size=200))
def test_arbitrary_text_raises_only_script_errors(text: str) -> None:
    _check_raises_only_script_errors(text)


@SETTINGS
@given(st.one_of(scripts(), mutated()))
def test_fmt_is_idempotent_and_preserves_the_program(text: str) -> None:
    try:
        before = parse(text, "prop.dial")
    except ScriptError:
        return
    once = format_text(text, "prop.dial")
    assert format_text(once, "prop.dial") == once
    assert parse(once, "prop.dial") == before


@given(st.text(alphabet=" \t=_aZ1é\u00a0\x1c"))
def test_parameters_without_quotes_take_the_lean_path_to_the_same_words(text: str) -> None:
    """The tokenizer's path for parameters without quotes (issue 26) against the general
    one: the same parameters, words and spans, or the same error."""

    def split(tokenize: Callable[[int, str, int], list[Param]]) -> object:
        code = "% g get_joints " + text
        try:
            params = tokenize(1, code, 14)
        except WordError as e:
            return e.span, e.message, e.known
        return [(p, p.span, [w.span for w in p.words], hash(p)) for p in params]

    assert split(words._unquoted) == split(words._general)
