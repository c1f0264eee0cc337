"""Hostile inputs (issue 15): every parser-side reproducer ends in a caret error or a result,
never an internal exception, a hang or a flood of output. The others are golden files
(tests/data/invalid: repeat_unicode_digits, count_too_long, mask_too_long, nesting_too_deep,
call_name_too_long, scene_name_too_long, drive_beyond_range)."""

from __future__ import annotations

from pathlib import Path

import pytest

from dial.errors import MAX_PROBLEMS, MAX_SHOWN, WINDOW, ScriptError
from dial.parser import TBlock, check_text, expand, load
from dial.parser.fmt import format_text
from dial.parser.show import render
from dial.parser.structure import MAX_NESTING
from dial.parser.timeline import length

GO = '% go puma_command "moves above"\n% t get_joints\n'


def _errors(text: str, path: str = "x.dial") -> list[str]:
    with pytest.raises(ScriptError) as info:
        check_text(text, path)
    info.value.render()
    return [d.header for d in info.value.diagnostics]


@pytest.mark.parametrize(
    ("text", "header"),
    [
        (
            GO + "@call a\x00.dial\n",
            "x.dial:3:8: the called script's path holds the control character U+0000 (NUL)",
        ),
        (
            GO + "@if t\n" * 1000 + "go #\n" + "@end\n" * 1000,
            f"x.dial:{3 + MAX_NESTING}:1: '@if' is nested 101 levels deep",
        ),
        (
            GO + "@repeat 1\n" * 500 + "go #\n" + "@end\n" * 500,
            f"x.dial:{3 + MAX_NESTING}:1: '@repeat' is nested 101 levels deep",
        ),
        (GO + "go #--- @call #=====\n", "x.dial:3:9: unexpected '@' in the diagram of 'go'"),
        ("@scene ~no_such_user/w.toml\n" + GO + "go #\n", "x.dial:1:8: unknown scene"),
    ],
    ids=["call-nul", "if-1000-deep", "repeat-500-deep", "diagram-backtracking", "scene-tilde"],
)
def test_reproducers_are_caret_errors(text: str, header: str) -> None:
    from dial.scene import load_scene_names

    with pytest.raises(ScriptError) as info:
        check_text(text, "x.dial", loader=load_scene_names)
    assert info.value.diagnostics[0].header.startswith(header)
    assert len(info.value.diagnostics) == 1


def test_many_problems_on_one_line_print_a_window_and_a_count() -> None:
    with pytest.raises(ScriptError) as info:
        check_text("% g get_joints " + "y=1 " * 25_000 + "\n", "x.dial")
    assert len(info.value.diagnostics) == MAX_PROBLEMS  # the check stops there (issue 26)
    out = info.value.render().splitlines()
    assert len(out) == 3 * MAX_SHOWN + 2
    assert out[-2] == f"x.dial: {MAX_PROBLEMS - MAX_SHOWN} more problems not shown"
    assert out[-1] == (
        f"x.dial:1:1: too many problems: the check stopped at line 1 after {MAX_PROBLEMS}; "
        "0 lines after it were not checked"
    )
    assert max(len(line) for line in out) < WINDOW + 20
    source, caret = out[-4], out[-3]
    assert source.startswith(" 1 | ...") and source.endswith("...")
    assert source[caret.index("^") :].startswith("y=1")


def test_the_check_of_a_file_stops_at_its_hundredth_problem(tmp_path: Path) -> None:
    """As compilers do (issue 26): syntax problems on 150 lines, then names in a callee."""
    (tmp_path / "sub.dial").write_text(GO + "nope #\n" * 120)
    main = tmp_path / "main.dial"
    main.write_text(GO + "@call sub.dial\n" + "?\n" * 150 + "go #\n")
    with pytest.raises(ScriptError) as info:
        load(main)
    with pytest.raises(ScriptError) as again:
        load(main)
    assert info.value.render() == again.value.render()  # deterministic
    headers = [d.header for d in info.value.diagnostics]
    assert len(headers) == MAX_PROBLEMS  # the parser stops: no callee is checked
    assert headers[0].startswith(f"{main}:4:1: unexpected '?'")
    assert headers[-1].startswith(f"{main}:103:1: unexpected '?'")
    cutoff = info.value.cutoffs[str(main)]
    assert cutoff.header == (
        f"{main}:103:1: too many problems: the check stopped at line 103 after "
        f"{MAX_PROBLEMS}; 51 lines after it were not checked"
    )
    assert info.value.render().endswith(cutoff.header)
    main.write_text(GO + "@call sub.dial\n")  # the callee's own 120 problems: capped in it
    with pytest.raises(ScriptError) as callee:
        load(main)
    assert len(callee.value.diagnostics) == MAX_PROBLEMS
    assert list(callee.value.cutoffs) == [str(tmp_path / "sub.dial")]
    assert callee.value.cutoffs[str(tmp_path / "sub.dial")].span.line == 102


def test_a_line_of_100000_runs_checks() -> None:
    script = check_text(GO + "go " + "#" * 100_000 + "\n", "x.dial")
    block = script.timeline[0]
    assert isinstance(block, TBlock) and len(block.runs) == 100_000


def test_counted_repeats_are_never_unrolled() -> None:
    text = GO + "@repeat 1000\n@repeat 1000\n@repeat 1000\ngo #=\n@end\n@end\n@end\n"
    script = check_text(text, "x.dial")
    assert length(script) == 2 * 1000**3
    layout = expand(script)
    assert layout.compact and layout.length == 2 and layout.expanded == 2 * 1000**3
    shown = render(script, layout)
    assert "2000000000 ticks" in shown and "shown compactly" in shown
    assert "@repeat 1000 (drawn once of 1000)" in shown


def test_a_million_repeats_show_compactly() -> None:
    script = check_text(GO + "@repeat 1000000\ngo #\n@end\n", "x.dial")
    shown = render(script)
    assert shown.splitlines()[0].endswith(", 1000000 ticks") and len(shown) < 2000


def test_a_small_timeline_is_still_expanded() -> None:
    layout = expand(check_text(GO + "@repeat 3\ngo #\n@end\n", "x.dial"))
    assert not layout.compact and layout.length == 3 == layout.expanded
    assert [s.label for s in layout.sections][-1] == "@repeat 3 (3/3)"


def test_a_long_script_shows_compactly_and_stops(tmp_path: Path) -> None:
    script = check_text(GO + "go #==\n\n" * 3000, "x.dial")
    layout = expand(script)
    assert layout.compact and layout.cut and layout.expanded == 9000
    assert "the chart stops after tick" in render(script, layout)


def _chain(tmp_path: Path, n: int, calls: int) -> Path:
    """Scripts s0 ... s{n-1}: each calls the next ``calls`` times; the last runs one tick."""
    for i in range(n):
        body = f"@call s{i + 1}.dial\n" * calls if i < n - 1 else "go #\n"
        (tmp_path / f"s{i}.dial").write_text(GO + body)
    return tmp_path / "s0.dial"


def test_a_call_dag_is_checked_once_per_script(tmp_path: Path) -> None:
    script = load(_chain(tmp_path, 40, 2))
    assert length(script) == 2**39  # laid out by arithmetic: 2^39 calls are never walked


def test_calls_count_towards_the_nesting_limit(tmp_path: Path) -> None:
    with pytest.raises(ScriptError) as info:
        load(_chain(tmp_path, 150, 1))
    (d,) = info.value.diagnostics
    # s0 calls s1 at level 1, ..., s99 calls s100 at level 100: s100's call is one too many.
    assert d.path.endswith(f"s{MAX_NESTING}.dial") and d.span.line == 3
    assert d.message.startswith(f"'@call' is nested {MAX_NESTING + 1} levels deep")
    assert d.message.endswith(f"(the calls that lead to this script take {MAX_NESTING})")


def test_a_callee_that_is_a_directory_is_a_caret_error(tmp_path: Path) -> None:
    (tmp_path / "dir.dial").mkdir()
    (tmp_path / "main.dial").write_text(GO + "@call dir.dial\n")
    assert _errors((tmp_path / "main.dial").read_text(), str(tmp_path / "main.dial")) == [
        f"{tmp_path / 'main.dial'}:3:7: cannot find called script 'dir.dial' (looked in {tmp_path})"
    ]


def test_fmt_of_a_long_ruler_like_comment_is_linear() -> None:
    comment = "//" + " " * 20_000 + "1" + " " * 20_000 + "x"  # no ruler: it ends in x
    assert format_text(GO + "go #\n" + comment + "\n").splitlines()[-1] == comment
