"""Golden files: valid scripts and their timelines, invalid scripts and their exact errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from dial.errors import ScriptError
from dial.parser import load
from dial.parser.show import render
from dial.scene import load_scene_names

from .conftest import DATA, golden

VALID = sorted((DATA / "valid").glob("*.dial"))
INVALID = sorted((DATA / "invalid").glob("*.dial"))


def test_there_are_enough_golden_files() -> None:
    assert len(VALID) >= 6
    assert len(INVALID) >= 40


@pytest.mark.parametrize("path", VALID, ids=lambda p: p.stem)
def test_valid_timeline(path: Path) -> None:
    script = load(path, loader=load_scene_names, display=path.name)
    golden(path.with_suffix(".show"), render(script))


@pytest.mark.parametrize("path", INVALID, ids=lambda p: p.stem)
def test_invalid_message(path: Path) -> None:
    with pytest.raises(ScriptError) as info:
        load(path, loader=load_scene_names, display=path.name)
    headers = "".join(d.header + "\n" for d in info.value.diagnostics)
    golden(path.with_suffix(".err"), headers)
    # Every message points into the file it names, with a caret under the span.
    for d in info.value.diagnostics:
        assert d.span.line >= 1 and d.span.col >= 1
        assert "^" in d.render()
