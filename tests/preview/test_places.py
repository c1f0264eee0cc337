"""Where program statements are written: a world file edited between two previews counts."""

from __future__ import annotations

from pathlib import Path

from dial.preview.places import Places, statement_place


def test_an_edited_world_file_is_read_again(tmp_path: Path) -> None:
    world = tmp_path / "w.toml"
    world.write_text('[programs]\nmine = """\nMOVE a\nMOVE b\n"""\n')
    assert statement_place(world, "mine", 2) == "w.toml:4"
    world.write_text('# a comment line\n[programs]\nmine = """\nMOVE a\nMOVE b\n"""\n')
    assert statement_place(world, "mine", 2) == "w.toml:5"


def test_extends_may_span_lines_and_names_the_later_base_first(tmp_path: Path) -> None:
    (tmp_path / "a.toml").write_text('[programs]\nshared = "MOVE a"\n')
    (tmp_path / "b.toml").write_text('\n[programs]\nshared = "MOVE b"\n')
    child = tmp_path / "c.toml"
    child.write_text('extends = [\n  "a.toml",\n  "b.toml",\n]\n[programs]\nown = "MOVE c"\n')
    places = Places()
    assert places.statement(child, "own", 1) == "c.toml:6"
    assert places.statement(child, "shared", 1) == "b.toml:3"  # the later base wins a merge
