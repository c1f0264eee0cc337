"""The docs say what the code does."""

from __future__ import annotations

from dial.cli import build_parser
from dial.parser.parse import DIRECTIVES

from .conftest import DATA, ROOT

LANGUAGE = (ROOT / "docs" / "language.md").read_text(encoding="utf-8")


def test_language_reference_covers_every_directive() -> None:
    for name in DIRECTIVES:
        assert f"`@{name}" in LANGUAGE, name


def test_language_reference_error_example_is_the_real_message() -> None:
    expected = (DATA / "invalid" / "force_out_of_range.err").read_text(encoding="utf-8").strip()
    assert expected in LANGUAGE


def test_readme_starts_with_the_two_commands() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    blocks = [b.split("```", 1)[0].strip() for b in readme.split("```sh\n")[1:3]]
    assert blocks[0].startswith("pip install -e . && dial ")
    assert blocks[1] == 'pip install -e ".[test]" && pytest'
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert blocks[1] in ci


def test_readme_lists_every_subcommand() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    for name in sub.choices:  # type: ignore[union-attr]
        assert f"`dial {name}" in readme, name


def test_instruction_reference_covers_every_instruction_and_parameter() -> None:
    from dial.instructions import INSTRUCTIONS

    doc = (ROOT / "docs" / "instructions.md").read_text(encoding="utf-8")
    headings = [line for line in doc.splitlines() if line.startswith("## ")]
    for name, instr in INSTRUCTIONS.items():
        assert any(f"`{name}" in h for h in headings), name
        for spec in instr.params:
            if spec.name in ("verb", "masks", "pose", "set", "dx", "dy", "dz", "rx", "ry", "rz"):
                continue  # positional: shown in the usage line
            assert f"{spec.name}=" in doc or f"`{spec.name}`" in doc, (name, spec.name)
        for verb in instr.verbs:
            assert f"`{verb} " in doc or f'"{verb} ' in doc, verb
