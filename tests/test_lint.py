"""The code base stays ruff-clean (lint and format) and type-checks (mypy --strict)."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from .conftest import ROOT


@pytest.mark.parametrize("args", [["check"], ["format", "--check"]])
def test_ruff(args: list[str]) -> None:
    ruff = shutil.which("ruff")
    assert ruff is not None, "ruff is part of the test extra: pip install -e '.[test]'"
    done = subprocess.run([ruff, *args, "."], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr


def test_mypy_strict() -> None:
    mypy = shutil.which("mypy")
    assert mypy is not None, "mypy is part of the test extra: pip install -e '.[test]'"
    done = subprocess.run([mypy, "dial"], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
