"""Helpers for the teaching tests."""

from __future__ import annotations

from pathlib import Path

import pytest

from dial.scene import worlds_dir


@pytest.fixture
def pour_copy(tmp_path: Path) -> Path:
    """pour.toml in a temporary directory, its [scene] paths made absolute."""
    worlds = worlds_dir()
    text = (worlds / "pour.toml").read_text(encoding="utf-8")
    text = text.replace('"../scene_pour.xml"', f'"{(worlds.parent / "scene_pour.xml").as_posix()}"')
    text = text.replace('"hand_poses.toml"', f'"{(worlds / "hand_poses.toml").as_posix()}"')
    path = tmp_path / "pour_copy.toml"
    path.write_text(text, encoding="utf-8")
    return path
