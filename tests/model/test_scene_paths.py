"""Every scene (and the robot) opens with plain MuJoCo by a relative path, from anywhere,
as Menagerie users expect (e.g. ``python -m mujoco.viewer --mjcf=...``)."""

from __future__ import annotations

import os
from pathlib import Path

import mujoco
import pytest

from dial.backend.model import load_model
from tests.conftest import ROOT

MODELS = ROOT / "models" / "utah_hand_puma"
FILES = [*sorted(p.name for p in MODELS.glob("scene_*.xml")), "utah_hand_puma.xml"]


@pytest.mark.parametrize("name", FILES)
@pytest.mark.parametrize("where", ["root", "elsewhere"])
def test_loads_by_a_relative_path(
    name: str, where: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    here = ROOT if where == "root" else tmp_path
    monkeypatch.chdir(here)
    model = mujoco.MjModel.from_xml_path(os.path.relpath(MODELS / name, here))
    assert "/" in os.path.relpath(MODELS / name, here)  # a folder in the path: the hard case
    reference = load_model(MODELS / name)  # dial's own loader
    assert (model.nbody, model.ngeom, model.nu, model.nsensor) == (
        reference.nbody,
        reference.ngeom,
        reference.nu,
        reference.nsensor,
    )
