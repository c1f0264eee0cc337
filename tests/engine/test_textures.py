"""A run that nothing draws compiles its scene without textures (issue 26: a fifth of the
compile); no physics reads them, so it logs and ends exactly as a run with them does."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dial
from dial.backend import model
from dial.engine import RunResult, Watched
from tests.conftest import json_records


class Looking:
    """An observer that only notes whether the scene it was shown has its textures."""

    def __init__(self) -> None:
        self.textures = -1

    def begin(self, run: Watched) -> None:
        self.textures = run.robot.model.ntex

    def period(self, periods: int, tick: int) -> None:
        pass

    def end(self, result: RunResult | None) -> None:
        pass


def test_a_run_without_textures_is_the_run_with_them(
    short_script: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    untextured: list[str] = []
    compile_bare = model.load_untextured
    monkeypatch.setattr(
        model,
        "load_untextured",
        lambda path, profile=None: untextured.append(str(path)) or compile_bare(path, profile),
    )
    bare = dial.run(short_script, perturb=5, seed=2)
    assert [Path(p).name for p in untextured] == ["scene_surface.xml"]
    looking = Looking()
    drawn = dial.run(short_script, perturb=5, seed=2, observers=[looking])
    assert looking.textures > 0 and len(untextured) == 1  # an observer sees it as drawn
    assert json_records(bare) == json_records(drawn)
    assert np.array(bare.final_qpos).tobytes() == np.array(drawn.final_qpos).tobytes()
    assert bare.physics_steps == drawn.physics_steps > 0
